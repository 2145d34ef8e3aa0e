/* animkit command line: particle scene files, read with the strict cli_json reader. */
#include "scene_particles.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_json.h"

#define BIG 1e9f

static const char* const integrator_names[] = {"euler", "symplectic", "verlet", "rk4", NULL};
static const ak_particles_integrator integrator_values[] = {
    AK_INTEGRATOR_EULER, AK_INTEGRATOR_SYMPLECTIC, AK_INTEGRATOR_VERLET, AK_INTEGRATOR_RK4};
static const char* const shape_names[] = {"point", "sphere", "sphere_surface", "disc", "box", NULL};

/* An optional array member allocated with count elements of size each (NULL when absent). */
static void* read_array(cli_json* j, const cJSON* root, const char* key, size_t size,
                        size_t* out_count, const cJSON** out_first) {
    *out_first = cli_json_array(j, root, "", key, PARTICLES_SCENE_MAX_ITEMS, out_count);
    if (j->failed || *out_count == 0) return NULL;
    void* p = calloc(*out_count, size);
    if (!p) cli_json_fail(j, "", key, "out of memory for %zu elements", *out_count);
    return p;
}

/* Restitution and friction of a collider: defaults 0.5 and 0. */
static void read_response(cli_json* j, const cJSON* o, const char* path, float* restitution,
                          float* friction) {
    *restitution = 0.5f;
    *friction = 0.0f;
    cli_json_float(j, o, path, "restitution", 0.0f, 1.0f, restitution);
    cli_json_float(j, o, path, "friction", 0.0f, BIG, friction);
}

/* [min, max] with 0 <= min <= max. */
static void read_range(cli_json* j, const cJSON* o, const char* path, const char* key, float* lo,
                       float* hi) {
    float r[2] = {*lo, *hi};
    if (cli_json_floats(j, o, path, key, 2, 0.0f, BIG, r) && r[0] > r[1])
        cli_json_fail(j, path, key, "the minimum %g is above the maximum %g", (double)r[0],
                      (double)r[1]);
    *lo = r[0];
    *hi = r[1];
}

/* One key of a "..._over_life" list: an array of exactly n finite numbers, the first (the life
 * fraction) in [0, 1] and above the previous key's, the others in [lo, hi]. */
static bool read_life_key(cli_json* j, const cJSON* e, const char* path, int n, float lo, float hi, float prev_t,
                          float* out) {
    if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != n)
        return cli_json_fail(j, path, NULL, "a key is an array of %d numbers [t, %s]", n,
                             n == 2 ? "size" : "r, g, b, a");
    int k = 0;
    for (const cJSON* v = e->child; v; v = v->next, ++k) {
        double x = cJSON_IsNumber(v) ? v->valuedouble : NAN;
        const double a = k ? lo : 0.0, b = k ? hi : 1.0;
        if (!(x >= a && x <= b)) return cli_json_fail(j, path, NULL, "value %d is not a number in [%g, %g]", k, a, b);
        out[k] = (float)x;
    }
    if (!(out[0] > prev_t)) return cli_json_fail(j, path, NULL, "t %g does not come after the previous key's %g", (double)out[0], (double)prev_t);
    return true;
}

/* "render": how the CLI and the viewer draw the particles (docs/particles.md). A texture that
 * is not a built-in name is a PNG path relative to the scene file. */
static void read_render(cli_json* j, const cJSON* root, const char* file, particles_scene* s) {
    const cJSON* r = cli_json_member(j, root, "", "render");
    if (!r || j->failed) return;
    static const char* const keys[] = {"style", "texture", "sheet", "frame_rate", "blend",
                                       "colour_over_life", "size_over_life", NULL};
    static const char* const styles[] = {"points", "sprites", NULL};
    static const char* const blends[] = {"alpha", "add", "cutout", NULL};
    if (!cli_json_object(j, r, "render", keys)) return;
    particles_sprites* sp = &s->sprites;
    int style = 0, blend = 0;
    cli_json_enum(j, r, "render", "style", styles, &style);
    sp->enabled = style == 1;
    cli_json_enum(j, r, "render", "blend", blends, &blend);
    sp->blend = blend == 2 ? AK_BLEND_OPAQUE : blend ? AK_BLEND_ADD : AK_BLEND_ALPHA;
    const char* tex = NULL;
    cli_json_str(j, r, "render", "texture", &tex);
    if (tex && strcmp(tex, "disc") == 0) sp->texture = AK_SPRITE_TEXTURE_DISC;
    else if (tex && strcmp(tex, "puff") == 0) sp->texture = AK_SPRITE_TEXTURE_PUFF;
    else if (tex) {
        size_t n = strlen(tex);
        if (n < 5 || strcmp(tex + n - 4, ".png") != 0) {
            cli_json_fail(j, "render", "texture", "\"%.80s\" is not disc, puff or a .png file", tex);
            return;
        }
        const char* slash = file ? strrchr(file, '/') : NULL;
        size_t dir = tex[0] == '/' || !slash ? 0 : (size_t)(slash - file) + 1;
        sp->sheet_path = malloc(dir + n + 1);
        if (!sp->sheet_path) {
            cli_json_fail(j, "render", "texture", "out of memory");
            return;
        }
        memcpy(sp->sheet_path, file, dir);
        memcpy(sp->sheet_path + dir, tex, n + 1);
    }
    float sheet[2] = {1, 1};
    if (cli_json_floats(j, r, "render", "sheet", 2, 1.0f, 64.0f, sheet) &&
        (sheet[0] != floorf(sheet[0]) || sheet[1] != floorf(sheet[1])))
        cli_json_fail(j, "render", "sheet", "[columns, rows] are whole numbers");
    sp->sheet_columns = (int)sheet[0], sp->sheet_rows = (int)sheet[1];
    sp->look.frame_count = (uint32_t)(sp->sheet_columns * sp->sheet_rows);
    cli_json_float(j, r, "render", "frame_rate", 0.0f, 1000.0f, &sp->look.frame_rate);
    char path[64];
    size_t n = 0;
    const cJSON* e = cli_json_array(j, r, "render", "colour_over_life", AK_PARTICLE_LOOK_MAX_KEYS, &n);
    for (size_t i = 0; i < n && e && !j->failed; ++i, e = e->next) {
        float v[5];
        cli_json_index(path, sizeof path, "render.colour_over_life", i);
        if (!read_life_key(j, e, path, 5, 0.0f, 16.0f, i ? sp->look.colour_keys[i - 1].t : -1.0f, v)) break;
        sp->look.colour_keys[i] = (ak_particle_colour_key){v[0], {v[1], v[2], v[3], v[4]}};
        sp->look.colour_key_count = (uint32_t)(i + 1);
    }
    e = cli_json_array(j, r, "render", "size_over_life", AK_PARTICLE_LOOK_MAX_KEYS, &n);
    for (size_t i = 0; i < n && e && !j->failed; ++i, e = e->next) {
        float v[2];
        cli_json_index(path, sizeof path, "render.size_over_life", i);
        if (!read_life_key(j, e, path, 2, 0.0f, 1000.0f, i ? sp->look.size_keys[i - 1].t : -1.0f, v)) break;
        sp->look.size_keys[i] = (ak_particle_size_key){v[0], v[1]};
        sp->look.size_key_count = (uint32_t)(i + 1);
    }
}

static void read_scene(cli_json* j, const cJSON* root, particles_scene* s) {
    static const char* const keys[] = {"dt",       "integrator",    "capacity",  "gravity",
                                       "drag",     "wind",          "particles", "springs",
                                       "planes",   "spheres",       "boxes",     "attractors",
                                       "vortices", "lennard_jones", "emitters",  "render", NULL};
    if (!cli_json_object(j, root, "", keys)) return;
    cli_json_float(j, root, "", "dt", 1e-7f, 10.0f, &s->dt);
    int integ = 1;
    if (cli_json_enum(j, root, "", "integrator", integrator_names, &integ))
        s->integrator = integrator_values[integ];
    ak_particles_world* w = &s->world;
    w->gravity = ak_vec3_make(0.0f, -9.81f, 0.0f);
    cli_json_vec3(j, root, "", "gravity", &w->gravity);
    cli_json_vec3(j, root, "", "wind", &w->wind);
    const cJSON* drag = cli_json_member(j, root, "", "drag");
    if (drag) {
        static const char* const dk[] = {"linear", "quadratic", NULL};
        cli_json_object(j, drag, "drag", dk);
        cli_json_float(j, drag, "drag", "linear", 0.0f, BIG, &w->drag_linear);
        cli_json_float(j, drag, "drag", "quadratic", 0.0f, BIG, &w->drag_quadratic);
    }
    const cJSON* lj = cli_json_member(j, root, "", "lennard_jones");
    if (lj) {
        static const char* const lk[] = {"epsilon", "sigma", "cutoff", NULL};
        cli_json_object(j, lj, "lennard_jones", lk);
        w->lennard_jones.sigma = 0.1f;
        cli_json_float(j, lj, "lennard_jones", "epsilon", 0.0f, BIG, &w->lennard_jones.epsilon);
        cli_json_float(j, lj, "lennard_jones", "sigma", 1e-6f, BIG, &w->lennard_jones.sigma);
        cli_json_float(j, lj, "lennard_jones", "cutoff", 0.0f, BIG, &w->lennard_jones.cutoff);
    }
    char path[64];
    size_t n = 0;
    const cJSON* e = NULL;

    s->particles =
        (ak_particle_init*)read_array(j, root, "particles", sizeof *s->particles, &n, &e);
    s->particle_count = s->particles ? n : 0;
    for (size_t i = 0; i < s->particle_count && !j->failed; ++i, e = e->next) {
        static const char* const pk[] = {"p", "v", "m", "lifetime", "size", "colour", NULL};
        cli_json_index(path, sizeof path, "particles", i);
        ak_particle_init* p = &s->particles[i];
        p->mass = 1.0f;
        float colour[4] = {1, 1, 1, 1};
        cli_json_object(j, e, path, pk);
        cli_json_vec3(j, e, path, "p", &p->position);
        cli_json_vec3(j, e, path, "v", &p->velocity);
        cli_json_float(j, e, path, "m", 0.0f, BIG, &p->mass);
        cli_json_float(j, e, path, "lifetime", 0.0f, BIG, &p->lifetime);
        cli_json_float(j, e, path, "size", 0.0f, BIG, &p->size);
        cli_json_floats(j, e, path, "colour", 4, 0.0f, 1.0f, colour);
        p->colour = ak_vec4_make(colour[0], colour[1], colour[2], colour[3]);
    }

    s->springs = (ak_particle_spring*)read_array(j, root, "springs", sizeof *s->springs, &n, &e);
    w->springs = (ak_particle_spring_cspan){s->springs, s->springs ? n : 0};
    for (size_t i = 0; i < w->springs.count && !j->failed; ++i, e = e->next) {
        static const char* const sk[] = {"i", "j", "rest", "k", "damping", NULL};
        cli_json_index(path, sizeof path, "springs", i);
        ak_particle_spring* sp = &s->springs[i];
        long a = 0, b = 0;
        const long last = (long)s->particle_count - 1;
        cli_json_object(j, e, path, sk);
        if (!cJSON_GetObjectItemCaseSensitive(e, "i") ||
            !cJSON_GetObjectItemCaseSensitive(e, "j")) {
            cli_json_fail(j, path, NULL, "a spring needs both \"i\" and \"j\"");
            break;
        }
        if (last < 0) {
            cli_json_fail(j, path, "i", "index out of range: the scene has no particles");
            break;
        }
        cli_json_int(j, e, path, "i", 0, last, &a);
        cli_json_int(j, e, path, "j", 0, last, &b);
        if (j->failed) break;
        if (a == b)
            cli_json_fail(j, path, "j", "a spring needs two different particles (i = j = %ld)", a);
        sp->i = (uint32_t)a;
        sp->j = (uint32_t)b;
        sp->rest = ak_vec3_distance(s->particles[a].position, s->particles[b].position);
        sp->k = 100.0f;
        cli_json_float(j, e, path, "rest", 0.0f, BIG, &sp->rest);
        cli_json_float(j, e, path, "k", 0.0f, BIG, &sp->k);
        cli_json_float(j, e, path, "damping", 0.0f, BIG, &sp->damping);
    }

    s->planes = (ak_particle_plane*)read_array(j, root, "planes", sizeof *s->planes, &n, &e);
    w->planes = (ak_particle_plane_cspan){s->planes, s->planes ? n : 0};
    for (size_t i = 0; i < w->planes.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"n", "d", "restitution", "friction", NULL};
        cli_json_index(path, sizeof path, "planes", i);
        ak_particle_plane* pl = &s->planes[i];
        pl->normal = ak_vec3_make(0, 1, 0);
        cli_json_object(j, e, path, k);
        cli_json_vec3(j, e, path, "n", &pl->normal);
        if (!j->failed && !(ak_vec3_length_sq(pl->normal) > 1e-12f))
            cli_json_fail(j, path, "n", "the normal is zero");
        cli_json_float(j, e, path, "d", -BIG, BIG, &pl->d);
        read_response(j, e, path, &pl->restitution, &pl->friction);
    }

    s->spheres = (ak_particle_sphere*)read_array(j, root, "spheres", sizeof *s->spheres, &n, &e);
    w->spheres = (ak_particle_sphere_cspan){s->spheres, s->spheres ? n : 0};
    for (size_t i = 0; i < w->spheres.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"c", "r", "restitution", "friction", NULL};
        cli_json_index(path, sizeof path, "spheres", i);
        ak_particle_sphere* sp = &s->spheres[i];
        sp->radius = 1.0f;
        cli_json_object(j, e, path, k);
        cli_json_vec3(j, e, path, "c", &sp->center);
        cli_json_float(j, e, path, "r", 0.0f, BIG, &sp->radius);
        read_response(j, e, path, &sp->restitution, &sp->friction);
    }

    s->boxes = (ak_particle_box*)read_array(j, root, "boxes", sizeof *s->boxes, &n, &e);
    w->boxes = (ak_particle_box_cspan){s->boxes, s->boxes ? n : 0};
    for (size_t i = 0; i < w->boxes.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"min", "max", "restitution", "friction", NULL};
        cli_json_index(path, sizeof path, "boxes", i);
        ak_particle_box* b = &s->boxes[i];
        b->min = ak_vec3_make(-0.5f, -0.5f, -0.5f);
        b->max = ak_vec3_make(0.5f, 0.5f, 0.5f);
        cli_json_object(j, e, path, k);
        cli_json_vec3(j, e, path, "min", &b->min);
        cli_json_vec3(j, e, path, "max", &b->max);
        if (!j->failed && (b->min.x > b->max.x || b->min.y > b->max.y || b->min.z > b->max.z))
            cli_json_fail(j, path, "max", "below min on some axis");
        read_response(j, e, path, &b->restitution, &b->friction);
    }

    s->attractors =
        (ak_particle_attractor*)read_array(j, root, "attractors", sizeof *s->attractors, &n, &e);
    w->attractors = (ak_particle_attractor_cspan){s->attractors, s->attractors ? n : 0};
    for (size_t i = 0; i < w->attractors.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"p", "strength", "softening", NULL};
        cli_json_index(path, sizeof path, "attractors", i);
        ak_particle_attractor* a = &s->attractors[i];
        a->strength = 1.0f;
        a->softening = 0.1f;
        cli_json_object(j, e, path, k);
        cli_json_vec3(j, e, path, "p", &a->position);
        cli_json_float(j, e, path, "strength", -BIG, BIG, &a->strength);
        cli_json_float(j, e, path, "softening", 0.0f, BIG, &a->softening);
    }

    s->vortices = (ak_particle_vortex*)read_array(j, root, "vortices", sizeof *s->vortices, &n, &e);
    w->vortices = (ak_particle_vortex_cspan){s->vortices, s->vortices ? n : 0};
    for (size_t i = 0; i < w->vortices.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"c", "axis", "strength", "softening", NULL};
        cli_json_index(path, sizeof path, "vortices", i);
        ak_particle_vortex* v = &s->vortices[i];
        v->axis = ak_vec3_make(0, 1, 0);
        v->strength = 1.0f;
        v->softening = 0.1f;
        cli_json_object(j, e, path, k);
        cli_json_vec3(j, e, path, "c", &v->center);
        cli_json_vec3(j, e, path, "axis", &v->axis);
        cli_json_float(j, e, path, "strength", -BIG, BIG, &v->strength);
        cli_json_float(j, e, path, "softening", 0.0f, BIG, &v->softening);
    }

    s->emitters =
        (ak_particle_emitter*)read_array(j, root, "emitters", sizeof *s->emitters, &n, &e);
    s->emitter_count = s->emitters ? n : 0;
    if (s->emitter_count) {
        s->bursts = (particles_burst*)calloc(s->emitter_count, sizeof *s->bursts);
        if (!s->bursts) cli_json_fail(j, "", "emitters", "out of memory");
    }
    for (size_t i = 0; i < s->emitter_count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {
            "shape", "center",   "radius",      "half_extents",   "direction", "cone_angle",
            "speed", "lifetime", "size",        "mass",           "colour",    "velocity",
            "rate",  "burst",    "burst_start", "burst_interval", NULL};
        cli_json_index(path, sizeof path, "emitters", i);
        ak_particle_emitter* em = &s->emitters[i];
        particles_burst* b = &s->bursts[i];
        int shape = 0;
        em->direction = ak_vec3_make(0, 1, 0);
        em->radius = 0.1f;
        em->half_extents = ak_vec3_make(0.5f, 0.5f, 0.5f);
        em->cone_angle = 0.3f;
        em->speed_min = 1.0f, em->speed_max = 2.0f;
        em->lifetime_min = 1.0f, em->lifetime_max = 2.0f;
        em->size_min = 0.03f, em->size_max = 0.03f;
        em->mass = 1.0f;
        float colour[4] = {1.0f, 0.6f, 0.2f, 1.0f};
        long burst = 0;
        cli_json_object(j, e, path, k);
        cli_json_enum(j, e, path, "shape", shape_names, &shape);
        em->shape = (ak_emitter_shape)shape;
        cli_json_vec3(j, e, path, "center", &em->center);
        cli_json_float(j, e, path, "radius", 0.0f, BIG, &em->radius);
        cli_json_vec3(j, e, path, "half_extents", &em->half_extents);
        if (!j->failed &&
            (em->half_extents.x < 0 || em->half_extents.y < 0 || em->half_extents.z < 0))
            cli_json_fail(j, path, "half_extents", "a negative extent");
        cli_json_vec3(j, e, path, "direction", &em->direction);
        cli_json_float(j, e, path, "cone_angle", 0.0f, AK_PI, &em->cone_angle);
        read_range(j, e, path, "speed", &em->speed_min, &em->speed_max);
        read_range(j, e, path, "lifetime", &em->lifetime_min, &em->lifetime_max);
        read_range(j, e, path, "size", &em->size_min, &em->size_max);
        cli_json_float(j, e, path, "mass", 1e-9f, BIG, &em->mass);
        cli_json_floats(j, e, path, "colour", 4, 0.0f, 1.0f, colour);
        em->colour = ak_vec4_make(colour[0], colour[1], colour[2], colour[3]);
        cli_json_vec3(j, e, path, "velocity", &em->base_velocity);
        cli_json_float(j, e, path, "rate", 0.0f, 1e8f, &em->rate);
        cli_json_int(j, e, path, "burst", 0, PARTICLES_SCENE_MAX_CAPACITY, &burst);
        b->count = (uint32_t)burst;
        cli_json_float(j, e, path, "burst_start", 0.0f, BIG, &b->start);
        cli_json_float(j, e, path, "burst_interval", 0.0f, BIG, &b->interval);
    }

    long cap = (long)s->particle_count + (s->emitter_count ? 100000 : 0);
    if (cap < 1) cap = 1;
    if (!j->failed && cJSON_GetObjectItemCaseSensitive(root, "capacity")) {
        cli_json_int(j, root, "", "capacity", 1, PARTICLES_SCENE_MAX_CAPACITY, &cap);
        if (!j->failed && (size_t)cap < s->particle_count)
            cli_json_fail(j, "", "capacity", "%ld is below the %zu particles listed", cap,
                          s->particle_count);
    }
    if (cap > (long)PARTICLES_SCENE_MAX_CAPACITY) cap = PARTICLES_SCENE_MAX_CAPACITY;
    s->capacity = (uint32_t)cap;
}

bool particles_scene_parse(const char* file, const char* text, size_t size, particles_scene* out,
                           char* err, size_t err_size) {
    memset(out, 0, sizeof *out);
    out->dt = 0.01f;
    out->integrator = AK_INTEGRATOR_SYMPLECTIC;
    cli_json j = {.file = file ? file : "(scene)"};
    cJSON* root = cli_json_parse(&j, text, size);
    if (root) read_scene(&j, root, out);
    if (root && !j.failed) read_render(&j, root, file, out);
    cJSON_Delete(root);
    if (j.failed) {
        if (err && err_size) snprintf(err, err_size, "%s", j.message); /* one line: cli_json says so */
        particles_scene_free(out);
        return false;
    }
    return true;
}

void particles_scene_free(particles_scene* s) {
    if (!s) return;
    free(s->particles);
    free(s->springs);
    free(s->planes);
    free(s->spheres);
    free(s->boxes);
    free(s->attractors);
    free(s->vortices);
    free(s->emitters);
    free(s->bursts);
    free(s->sprites.sheet_path);
    memset(s, 0, sizeof *s);
}
