/* animkit particles: scene files (JSON, read with the strict reader of src/json.h) and presets. */
#include <animkit/particles.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

#define BIG 1e9f

/* ---- presets -------------------------------------------------------------------------- */

static ak_particle_emitter emitter_base(void) {
    ak_particle_emitter e = {.direction = {0, 1, 0},
                             .cone_angle = 0.3f,
                             .speed_min = 1,
                             .speed_max = 2,
                             .lifetime_min = 1,
                             .lifetime_max = 2,
                             .size_min = 0.03f,
                             .size_max = 0.03f,
                             .mass = 1};
    return e;
}

/* Rain: emitter_base falling straight down (a narrow cone) from a flat box. */
static ak_particle_emitter rain_base(ak_vec3 center, ak_vec3 half_extents) {
    ak_particle_emitter e = emitter_base();
    e.shape = AK_EMITTER_BOX, e.center = center, e.half_extents = half_extents;
    e.direction = ak_vec3_make(0, -1, 0), e.cone_angle = 0.02f;
    return e;
}

/* Fills s for a preset; false when out of memory. */
static bool preset_fill(const char* name, ak_particles_scene* s) {
    memset(s, 0, sizeof *s);
    s->dt = 0.01f;
    s->integrator = AK_INTEGRATOR_SYMPLECTIC;
    s->capacity = 60000;
    s->world.gravity = ak_vec3_make(0, -9.81f, 0);
    s->planes = calloc(1, sizeof *s->planes);
    s->spheres = calloc(1, sizeof *s->spheres);
    s->emitters = calloc(4, sizeof *s->emitters);
    s->bursts = calloc(4, sizeof *s->bursts);
    if (!s->planes || !s->spheres || !s->emitters || !s->bursts) return false;
    s->planes[0] = (ak_particle_plane){.normal = {0, 1, 0}, .restitution = 0.4f, .friction = 0.3f};
    s->world.planes = (ak_particle_plane_cspan){s->planes, 1};
    ak_particle_emitter e = emitter_base();
    ak_particles_scene_sprites* look = &s->sprites;
    if (strcmp(name, "fountain") == 0) {
        /* droplets of 6 mm radius (they were 3 cm: 4500 touching balls read as one blob) */
        e.center = ak_vec3_make(0, 0.05f, 0);
        e.size_min = 0.005f, e.size_max = 0.007f;
        e.cone_angle = 0.18f, e.speed_min = 5.0f, e.speed_max = 5.6f;
        e.lifetime_min = 2.5f, e.lifetime_max = 3.5f;
        e.colour = ak_vec4_make(0.25f, 0.55f, 1.0f, 1), e.rate = 1500.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->spheres[0] = (ak_particle_sphere){
            .center = {0.45f, 0.35f, 0}, .radius = 0.35f, .restitution = 0.3f, .friction = 0.2f};
        s->world.spheres = (ak_particle_sphere_cspan){s->spheres, 1};
        s->world.drag_linear = 0.02f;
    } else if (strcmp(name, "rain") == 0) {
        e = rain_base(ak_vec3_make(0, 4, 0), ak_vec3_make(2, 0.1f, 2));
        e.speed_min = 3, e.speed_max = 4;
        e.lifetime_min = 2.5f, e.lifetime_max = 3.0f, e.size_min = 0.015f, e.size_max = 0.02f;
        e.colour = ak_vec4_make(0.55f, 0.7f, 1.0f, 1), e.rate = 3000.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->spheres[0] = (ak_particle_sphere){
            .center = {0, 1.2f, 0}, .radius = 0.8f, .restitution = 0.2f, .friction = 0.1f};
        s->world.spheres = (ak_particle_sphere_cspan){s->spheres, 1};
        s->world.wind = ak_vec3_make(1.5f, 0, 0);
        s->world.drag_linear = 0.3f;
        s->planes[0].restitution = 0.1f;
    } else if (strcmp(name, "fireworks") == 0) {
        const ak_vec4 colours[4] = {
            {1, 0.3f, 0.2f, 1}, {0.3f, 1, 0.4f, 1}, {1, 0.85f, 0.3f, 1}, {0.6f, 0.5f, 1, 1}};
        const float x[4] = {-1.2f, 0.9f, 0.0f, 1.6f}, y[4] = {3.0f, 3.6f, 4.2f, 2.8f};
        for (int k = 0; k < 4; ++k) {
            ak_particle_emitter f = emitter_base();
            f.shape = AK_EMITTER_SPHERE, f.center = ak_vec3_make(x[k], y[k], -0.5f * k),
            f.radius = 0.05f;
            f.cone_angle = AK_PI, f.speed_min = 2.5f, f.speed_max = 3.2f, f.lifetime_min = 1.2f,
            f.lifetime_max = 1.8f;
            f.colour = colours[k];
            s->emitters[k] = f;
            s->bursts[k] =
                (ak_particles_scene_burst){.count = 800, .start = 0.45f * (float)k, .interval = 1.8f};
        }
        s->emitter_count = 4;
        s->world.drag_quadratic = 0.02f;
        s->world.gravity = ak_vec3_make(0, -3.0f, 0);
    } else if (strcmp(name, "character") == 0) {
        /* Rain on the character (collides with its posed mesh) and sparks from its surface. */
        e = rain_base(ak_vec3_make(0, 2.6f, 0), ak_vec3_make(0.7f, 0.05f, 0.7f));
        e.speed_min = 2, e.speed_max = 2.5f;
        e.lifetime_min = 2, e.lifetime_max = 2.5f, e.size_min = 0.012f, e.size_max = 0.016f;
        e.colour = ak_vec4_make(0.45f, 0.65f, 1.0f, 1), e.rate = 2500.0f;
        s->emitters[0] = e;
        ak_particle_emitter sp = emitter_base();
        sp.shape = AK_EMITTER_MESH, sp.cone_angle = 0.5f, sp.speed_min = 0.3f, sp.speed_max = 0.8f;
        sp.lifetime_min = 0.6f, sp.lifetime_max = 1.0f, sp.size_min = 0.01f, sp.size_max = 0.015f;
        sp.colour = ak_vec4_make(1.0f, 0.55f, 0.15f, 1), sp.rate = 800.0f,
        sp.base_velocity = ak_vec3_make(0, 0.5f, 0);
        s->emitters[1] = sp;
        s->emitter_count = 2;
        s->planes[0].restitution = 0.2f;
    } else if (strcmp(name, "fire") == 0) {
        /* Flames: additive puffs rising from a disc, hot yellow to red to nothing while they
         * shrink, buoyant (gravity up) and slowed by the air; each puff plays a 4x4 sheet. */
        e.shape = AK_EMITTER_DISC, e.radius = 0.22f, e.center = ak_vec3_make(0, 0.02f, 0);
        e.cone_angle = 0.2f, e.speed_min = 0.8f, e.speed_max = 1.4f;
        e.lifetime_min = 0.6f, e.lifetime_max = 1.1f, e.size_min = 0.08f, e.size_max = 0.12f;
        e.colour = ak_vec4_make(1.0f, 0.62f, 0.22f, 1), e.rate = 350.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->world.gravity = ak_vec3_make(0, 2.0f, 0);
        s->world.drag_linear = 0.8f;
        look->enabled = true, look->texture = AK_SPRITE_TEXTURE_PUFF, look->sheet_columns = 4,
        look->sheet_rows = 4;
        look->blend = AK_BLEND_ADD;
        look->look = (ak_particle_look){.colour_keys = {{0.0f, {1.0f, 1.0f, 0.75f, 0.3f}},
                                                        {0.3f, {1.0f, 0.75f, 0.45f, 0.3f}},
                                                        {0.7f, {0.9f, 0.35f, 0.25f, 0.2f}},
                                                        {1.0f, {0.5f, 0.2f, 0.2f, 0.0f}}},
                                        .colour_key_count = 4,
                                        .size_keys = {{0.0f, 0.7f}, {0.35f, 1.0f}, {1.0f, 0.35f}},
                                        .size_key_count = 3,
                                        .frame_count = 16};
    } else if (strcmp(name, "smoke") == 0) {
        /* Smoke: few large puffs drifting up and downwind, fading in then out while they grow
         * and lighten; alpha-blended back to front. */
        e.shape = AK_EMITTER_DISC, e.radius = 0.12f, e.center = ak_vec3_make(0, 0.05f, 0);
        e.cone_angle = 0.3f, e.speed_min = 0.5f, e.speed_max = 0.8f;
        e.lifetime_min = 3.0f, e.lifetime_max = 4.0f, e.size_min = 0.12f, e.size_max = 0.18f;
        e.colour = ak_vec4_make(0.42f, 0.42f, 0.45f, 1), e.rate = 40.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->world.gravity = ak_vec3_make(0, 0.25f, 0);
        s->world.wind = ak_vec3_make(0.5f, 0, 0);
        s->world.drag_linear = 0.6f;
        look->enabled = true, look->texture = AK_SPRITE_TEXTURE_PUFF, look->sheet_columns = 4,
        look->sheet_rows = 2;
        look->blend = AK_BLEND_ALPHA;
        look->look = (ak_particle_look){.colour_keys = {{0.0f, {0.8f, 0.8f, 0.8f, 0.0f}},
                                                        {0.1f, {1.0f, 1.0f, 1.0f, 0.75f}},
                                                        {1.0f, {1.9f, 1.9f, 1.9f, 0.0f}}},
                                        .colour_key_count = 3,
                                        .size_keys = {{0.0f, 0.6f}, {1.0f, 3.0f}},
                                        .size_key_count = 2,
                                        .frame_count = 8,
                                        .frame_rate = 2.0f};
    } else {
        return false;
    }
    return true;
}

/* The names preset_fill knows (AK_PARTICLES_SCENE_PRESETS in words). */
static bool preset_known(const char* name) {
    static const char* const names[] = {"fountain",  "rain", "fireworks",
                                        "character", "fire", "smoke"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k)
        if (strcmp(name, names[k]) == 0) return true;
    return false;
}

static const char* const integrator_names[] = {"euler", "symplectic", "verlet", "rk4", NULL};
static const ak_particles_integrator integrator_values[] = {
    AK_INTEGRATOR_EULER, AK_INTEGRATOR_SYMPLECTIC, AK_INTEGRATOR_VERLET, AK_INTEGRATOR_RK4};
static const char* const shape_names[] = {"point", "sphere", "sphere_surface", "disc", "box", NULL};

/* An optional array member allocated with count elements of size each (NULL when absent). */
static void* read_array(akp_json* j, const cJSON* root, const char* key, size_t size,
                        size_t* out_count, const cJSON** out_first) {
    *out_first = akp_json_array(j, root, "", key, AK_PARTICLES_SCENE_MAX_ITEMS, out_count);
    if (j->failed || *out_count == 0) return NULL;
    void* p = calloc(*out_count, size);
    if (!p) akp_json_fail(j, "", key, "out of memory for %zu elements", *out_count);
    return p;
}

/* Restitution and friction of a collider: defaults 0.5 and 0. */
static void read_response(akp_json* j, const cJSON* o, const char* path, float* restitution,
                          float* friction) {
    *restitution = 0.5f;
    *friction = 0.0f;
    akp_json_float(j, o, path, "restitution", 0.0f, 1.0f, restitution);
    akp_json_float(j, o, path, "friction", 0.0f, BIG, friction);
}

/* [min, max] with 0 <= min <= max. */
static void read_range(akp_json* j, const cJSON* o, const char* path, const char* key, float* lo,
                       float* hi) {
    float r[2] = {*lo, *hi};
    if (akp_json_floats(j, o, path, key, 2, 0.0f, BIG, r) && r[0] > r[1])
        akp_json_fail(j, path, key, "the minimum %g is above the maximum %g", (double)r[0],
                      (double)r[1]);
    *lo = r[0];
    *hi = r[1];
}

/* One key of a "..._over_life" list: an array of exactly n finite numbers, the first (the life
 * fraction) in [0, 1] and above the previous key's, the others in [lo, hi]. */
static bool read_life_key(akp_json* j, const cJSON* e, const char* path, int n, float lo, float hi,
                          float prev_t, float* out) {
    if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != n)
        return akp_json_fail(j, path, NULL, "a key is an array of %d numbers [t, %s]", n,
                             n == 2 ? "size" : "r, g, b, a");
    int k = 0;
    for (const cJSON* v = e->child; v; v = v->next, ++k) {
        double x = cJSON_IsNumber(v) ? v->valuedouble : NAN;
        const double a = k ? lo : 0.0, b = k ? hi : 1.0;
        if (!(x >= a && x <= b))
            return akp_json_fail(j, path, NULL, "value %d is not a number in [%g, %g]", k, a, b);
        out[k] = (float)x;
    }
    if (!(out[0] > prev_t))
        return akp_json_fail(j, path, NULL, "t %g does not come after the previous key's %g",
                             (double)out[0], (double)prev_t);
    return true;
}

/* "render": how the CLI and the viewer draw the particles (docs/particles.md). A texture that
 * is not a built-in name is a PNG path relative to the scene file. */
static void read_render(akp_json* j, const cJSON* root, const char* file, ak_particles_scene* s) {
    const cJSON* r = akp_json_member(j, root, "", "render");
    if (!r || j->failed) return;
    static const char* const keys[] = {"style", "texture",          "sheet",          "frame_rate",
                                       "blend", "colour_over_life", "size_over_life", NULL};
    static const char* const styles[] = {"points", "sprites", NULL};
    static const char* const blends[] = {"alpha", "add", "cutout", NULL};
    if (!akp_json_object(j, r, "render", keys)) return;
    ak_particles_scene_sprites* sp = &s->sprites;
    int style = 0, blend = 0;
    akp_json_enum(j, r, "render", "style", styles, &style);
    sp->enabled = style == 1;
    akp_json_enum(j, r, "render", "blend", blends, &blend);
    sp->blend = blend == 2 ? AK_BLEND_OPAQUE : blend ? AK_BLEND_ADD : AK_BLEND_ALPHA;
    const char* tex = NULL;
    akp_json_str(j, r, "render", "texture", &tex);
    if (tex && strcmp(tex, "disc") == 0)
        sp->texture = AK_SPRITE_TEXTURE_DISC;
    else if (tex && strcmp(tex, "puff") == 0)
        sp->texture = AK_SPRITE_TEXTURE_PUFF;
    else if (tex) {
        size_t n = strlen(tex);
        if (n < 5 || strcmp(tex + n - 4, ".png") != 0) {
            akp_json_fail(j, "render", "texture", "\"%.80s\" is not disc, puff or a .png file",
                          tex);
            return;
        }
        const char* slash = file ? strrchr(file, '/') : NULL;
        size_t dir = tex[0] == '/' || !slash ? 0 : (size_t)(slash - file) + 1;
        sp->sheet_path = malloc(dir + n + 1);
        if (!sp->sheet_path) {
            akp_json_fail(j, "render", "texture", "out of memory");
            return;
        }
        if (dir) memcpy(sp->sheet_path, file, dir);
        memcpy(sp->sheet_path + dir, tex, n + 1);
    }
    float sheet[2] = {1, 1};
    if (akp_json_floats(j, r, "render", "sheet", 2, 1.0f, 64.0f, sheet) &&
        (sheet[0] != floorf(sheet[0]) || sheet[1] != floorf(sheet[1])))
        akp_json_fail(j, "render", "sheet", "[columns, rows] are whole numbers");
    sp->sheet_columns = (int)sheet[0], sp->sheet_rows = (int)sheet[1];
    sp->look.frame_count = (uint32_t)(sp->sheet_columns * sp->sheet_rows);
    akp_json_float(j, r, "render", "frame_rate", 0.0f, 1000.0f, &sp->look.frame_rate);
    char path[64];
    size_t n = 0;
    const cJSON* e =
        akp_json_array(j, r, "render", "colour_over_life", AK_PARTICLE_LOOK_MAX_KEYS, &n);
    for (size_t i = 0; i < n && e && !j->failed; ++i, e = e->next) {
        float v[5];
        akp_json_index(path, sizeof path, "render.colour_over_life", i);
        if (!read_life_key(j, e, path, 5, 0.0f, 16.0f, i ? sp->look.colour_keys[i - 1].t : -1.0f,
                           v))
            break;
        sp->look.colour_keys[i] = (ak_particle_colour_key){v[0], {v[1], v[2], v[3], v[4]}};
        sp->look.colour_key_count = (uint32_t)(i + 1);
    }
    e = akp_json_array(j, r, "render", "size_over_life", AK_PARTICLE_LOOK_MAX_KEYS, &n);
    for (size_t i = 0; i < n && e && !j->failed; ++i, e = e->next) {
        float v[2];
        akp_json_index(path, sizeof path, "render.size_over_life", i);
        if (!read_life_key(j, e, path, 2, 0.0f, 1000.0f, i ? sp->look.size_keys[i - 1].t : -1.0f,
                           v))
            break;
        sp->look.size_keys[i] = (ak_particle_size_key){v[0], v[1]};
        sp->look.size_key_count = (uint32_t)(i + 1);
    }
}

static void read_scene(akp_json* j, const cJSON* root, ak_particles_scene* s) {
    static const char* const keys[] = {"dt",       "integrator",    "capacity",  "gravity",
                                       "drag",     "wind",          "particles", "springs",
                                       "planes",   "spheres",       "boxes",     "attractors",
                                       "vortices", "lennard_jones", "emitters",  "render", NULL};
    if (!akp_json_object(j, root, "", keys)) return;
    akp_json_float(j, root, "", "dt", 1e-7f, 10.0f, &s->dt);
    int integ = 1;
    if (akp_json_enum(j, root, "", "integrator", integrator_names, &integ))
        s->integrator = integrator_values[integ];
    ak_particles_world* w = &s->world;
    w->gravity = ak_vec3_make(0.0f, -9.81f, 0.0f);
    akp_json_vec3(j, root, "", "gravity", &w->gravity);
    akp_json_vec3(j, root, "", "wind", &w->wind);
    const cJSON* drag = akp_json_member(j, root, "", "drag");
    if (drag) {
        static const char* const dk[] = {"linear", "quadratic", NULL};
        akp_json_object(j, drag, "drag", dk);
        akp_json_float(j, drag, "drag", "linear", 0.0f, BIG, &w->drag_linear);
        akp_json_float(j, drag, "drag", "quadratic", 0.0f, BIG, &w->drag_quadratic);
    }
    const cJSON* lj = akp_json_member(j, root, "", "lennard_jones");
    if (lj) {
        static const char* const lk[] = {"epsilon", "sigma", "cutoff", NULL};
        akp_json_object(j, lj, "lennard_jones", lk);
        w->lennard_jones.sigma = 0.1f;
        akp_json_float(j, lj, "lennard_jones", "epsilon", 0.0f, BIG, &w->lennard_jones.epsilon);
        akp_json_float(j, lj, "lennard_jones", "sigma", 1e-6f, BIG, &w->lennard_jones.sigma);
        akp_json_float(j, lj, "lennard_jones", "cutoff", 0.0f, BIG, &w->lennard_jones.cutoff);
    }
    char path[64];
    size_t n = 0;
    const cJSON* e = NULL;

    s->particles =
        (ak_particle_init*)read_array(j, root, "particles", sizeof *s->particles, &n, &e);
    s->particle_count = s->particles ? n : 0;
    for (size_t i = 0; i < s->particle_count && !j->failed; ++i, e = e->next) {
        static const char* const pk[] = {"p", "v", "m", "lifetime", "size", "colour", NULL};
        akp_json_index(path, sizeof path, "particles", i);
        ak_particle_init* p = &s->particles[i];
        p->mass = 1.0f;
        float colour[4] = {1, 1, 1, 1};
        akp_json_object(j, e, path, pk);
        akp_json_vec3(j, e, path, "p", &p->position);
        akp_json_vec3(j, e, path, "v", &p->velocity);
        akp_json_float(j, e, path, "m", 0.0f, BIG, &p->mass);
        akp_json_float(j, e, path, "lifetime", 0.0f, BIG, &p->lifetime);
        akp_json_float(j, e, path, "size", 0.0f, BIG, &p->size);
        akp_json_floats(j, e, path, "colour", 4, 0.0f, 1.0f, colour);
        p->colour = ak_vec4_make(colour[0], colour[1], colour[2], colour[3]);
    }

    s->springs = (ak_particle_spring*)read_array(j, root, "springs", sizeof *s->springs, &n, &e);
    w->springs = (ak_particle_spring_cspan){s->springs, s->springs ? n : 0};
    for (size_t i = 0; i < w->springs.count && !j->failed; ++i, e = e->next) {
        static const char* const sk[] = {"i", "j", "rest", "k", "damping", NULL};
        akp_json_index(path, sizeof path, "springs", i);
        ak_particle_spring* sp = &s->springs[i];
        long a = 0, b = 0;
        const long last = (long)s->particle_count - 1;
        akp_json_object(j, e, path, sk);
        if (!cJSON_GetObjectItemCaseSensitive(e, "i") ||
            !cJSON_GetObjectItemCaseSensitive(e, "j")) {
            akp_json_fail(j, path, NULL, "a spring needs both \"i\" and \"j\"");
            break;
        }
        if (last < 0) {
            akp_json_fail(j, path, "i", "index out of range: the scene has no particles");
            break;
        }
        akp_json_int(j, e, path, "i", 0, last, &a);
        akp_json_int(j, e, path, "j", 0, last, &b);
        if (j->failed) break;
        if (a == b)
            akp_json_fail(j, path, "j", "a spring needs two different particles (i = j = %ld)", a);
        sp->i = (uint32_t)a;
        sp->j = (uint32_t)b;
        sp->rest = ak_vec3_distance(s->particles[a].position, s->particles[b].position);
        sp->k = 100.0f;
        akp_json_float(j, e, path, "rest", 0.0f, BIG, &sp->rest);
        akp_json_float(j, e, path, "k", 0.0f, BIG, &sp->k);
        akp_json_float(j, e, path, "damping", 0.0f, BIG, &sp->damping);
    }

    s->planes = (ak_particle_plane*)read_array(j, root, "planes", sizeof *s->planes, &n, &e);
    w->planes = (ak_particle_plane_cspan){s->planes, s->planes ? n : 0};
    for (size_t i = 0; i < w->planes.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"n", "d", "restitution", "friction", NULL};
        akp_json_index(path, sizeof path, "planes", i);
        ak_particle_plane* pl = &s->planes[i];
        pl->normal = ak_vec3_make(0, 1, 0);
        akp_json_object(j, e, path, k);
        akp_json_vec3(j, e, path, "n", &pl->normal);
        if (!j->failed && !(ak_vec3_length_sq(pl->normal) > 1e-12f))
            akp_json_fail(j, path, "n", "the normal is zero");
        akp_json_float(j, e, path, "d", -BIG, BIG, &pl->d);
        read_response(j, e, path, &pl->restitution, &pl->friction);
    }

    s->spheres = (ak_particle_sphere*)read_array(j, root, "spheres", sizeof *s->spheres, &n, &e);
    w->spheres = (ak_particle_sphere_cspan){s->spheres, s->spheres ? n : 0};
    for (size_t i = 0; i < w->spheres.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"c", "r", "restitution", "friction", NULL};
        akp_json_index(path, sizeof path, "spheres", i);
        ak_particle_sphere* sp = &s->spheres[i];
        sp->radius = 1.0f;
        akp_json_object(j, e, path, k);
        akp_json_vec3(j, e, path, "c", &sp->center);
        akp_json_float(j, e, path, "r", 0.0f, BIG, &sp->radius);
        read_response(j, e, path, &sp->restitution, &sp->friction);
    }

    s->boxes = (ak_particle_box*)read_array(j, root, "boxes", sizeof *s->boxes, &n, &e);
    w->boxes = (ak_particle_box_cspan){s->boxes, s->boxes ? n : 0};
    for (size_t i = 0; i < w->boxes.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"min", "max", "restitution", "friction", NULL};
        akp_json_index(path, sizeof path, "boxes", i);
        ak_particle_box* b = &s->boxes[i];
        b->min = ak_vec3_make(-0.5f, -0.5f, -0.5f);
        b->max = ak_vec3_make(0.5f, 0.5f, 0.5f);
        akp_json_object(j, e, path, k);
        akp_json_vec3(j, e, path, "min", &b->min);
        akp_json_vec3(j, e, path, "max", &b->max);
        if (!j->failed && (b->min.x > b->max.x || b->min.y > b->max.y || b->min.z > b->max.z))
            akp_json_fail(j, path, "max", "below min on some axis");
        read_response(j, e, path, &b->restitution, &b->friction);
    }

    s->attractors =
        (ak_particle_attractor*)read_array(j, root, "attractors", sizeof *s->attractors, &n, &e);
    w->attractors = (ak_particle_attractor_cspan){s->attractors, s->attractors ? n : 0};
    for (size_t i = 0; i < w->attractors.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"p", "strength", "softening", NULL};
        akp_json_index(path, sizeof path, "attractors", i);
        ak_particle_attractor* a = &s->attractors[i];
        a->strength = 1.0f;
        a->softening = 0.1f;
        akp_json_object(j, e, path, k);
        akp_json_vec3(j, e, path, "p", &a->position);
        akp_json_float(j, e, path, "strength", -BIG, BIG, &a->strength);
        akp_json_float(j, e, path, "softening", 0.0f, BIG, &a->softening);
    }

    s->vortices = (ak_particle_vortex*)read_array(j, root, "vortices", sizeof *s->vortices, &n, &e);
    w->vortices = (ak_particle_vortex_cspan){s->vortices, s->vortices ? n : 0};
    for (size_t i = 0; i < w->vortices.count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {"c", "axis", "strength", "softening", NULL};
        akp_json_index(path, sizeof path, "vortices", i);
        ak_particle_vortex* v = &s->vortices[i];
        v->axis = ak_vec3_make(0, 1, 0);
        v->strength = 1.0f;
        v->softening = 0.1f;
        akp_json_object(j, e, path, k);
        akp_json_vec3(j, e, path, "c", &v->center);
        akp_json_vec3(j, e, path, "axis", &v->axis);
        akp_json_float(j, e, path, "strength", -BIG, BIG, &v->strength);
        akp_json_float(j, e, path, "softening", 0.0f, BIG, &v->softening);
    }

    s->emitters =
        (ak_particle_emitter*)read_array(j, root, "emitters", sizeof *s->emitters, &n, &e);
    s->emitter_count = s->emitters ? n : 0;
    if (s->emitter_count) {
        s->bursts = (ak_particles_scene_burst*)calloc(s->emitter_count, sizeof *s->bursts);
        if (!s->bursts) akp_json_fail(j, "", "emitters", "out of memory");
    }
    for (size_t i = 0; i < s->emitter_count && !j->failed; ++i, e = e->next) {
        static const char* const k[] = {
            "shape", "center",   "radius",      "half_extents",   "direction", "cone_angle",
            "speed", "lifetime", "size",        "mass",           "colour",    "velocity",
            "rate",  "burst",    "burst_start", "burst_interval", NULL};
        akp_json_index(path, sizeof path, "emitters", i);
        ak_particle_emitter* em = &s->emitters[i];
        ak_particles_scene_burst* b = &s->bursts[i];
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
        akp_json_object(j, e, path, k);
        akp_json_enum(j, e, path, "shape", shape_names, &shape);
        em->shape = (ak_emitter_shape)shape;
        akp_json_vec3(j, e, path, "center", &em->center);
        akp_json_float(j, e, path, "radius", 0.0f, BIG, &em->radius);
        akp_json_vec3(j, e, path, "half_extents", &em->half_extents);
        if (!j->failed &&
            (em->half_extents.x < 0 || em->half_extents.y < 0 || em->half_extents.z < 0))
            akp_json_fail(j, path, "half_extents", "a negative extent");
        akp_json_vec3(j, e, path, "direction", &em->direction);
        akp_json_float(j, e, path, "cone_angle", 0.0f, AK_PI, &em->cone_angle);
        read_range(j, e, path, "speed", &em->speed_min, &em->speed_max);
        read_range(j, e, path, "lifetime", &em->lifetime_min, &em->lifetime_max);
        read_range(j, e, path, "size", &em->size_min, &em->size_max);
        akp_json_float(j, e, path, "mass", 1e-9f, BIG, &em->mass);
        akp_json_floats(j, e, path, "colour", 4, 0.0f, 1.0f, colour);
        em->colour = ak_vec4_make(colour[0], colour[1], colour[2], colour[3]);
        akp_json_vec3(j, e, path, "velocity", &em->base_velocity);
        akp_json_float(j, e, path, "rate", 0.0f, 1e8f, &em->rate);
        akp_json_int(j, e, path, "burst", 0, AK_PARTICLES_SCENE_MAX_CAPACITY, &burst);
        b->count = (uint32_t)burst;
        akp_json_float(j, e, path, "burst_start", 0.0f, BIG, &b->start);
        akp_json_float(j, e, path, "burst_interval", 0.0f, BIG, &b->interval);
    }

    long cap = (long)s->particle_count + (s->emitter_count ? 100000 : 0);
    if (cap < 1) cap = 1;
    if (!j->failed && cJSON_GetObjectItemCaseSensitive(root, "capacity")) {
        akp_json_int(j, root, "", "capacity", 1, AK_PARTICLES_SCENE_MAX_CAPACITY, &cap);
        if (!j->failed && (size_t)cap < s->particle_count)
            akp_json_fail(j, "", "capacity", "%ld is below the %zu particles listed", cap,
                          s->particle_count);
    }
    if (cap > (long)AK_PARTICLES_SCENE_MAX_CAPACITY) cap = AK_PARTICLES_SCENE_MAX_CAPACITY;
    s->capacity = (uint32_t)cap;
}

ak_result ak_particles_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                       ak_particles_scene* out_scene, ak_diag* out_diag) {
    if (!out_scene) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, name ? name : "(scene)", "no scene to fill");
    memset(out_scene, 0, sizeof *out_scene);
    out_scene->dt = 0.01f;
    out_scene->integrator = AK_INTEGRATOR_SYMPLECTIC;
    akp_json j = {.file = name ? name : "(scene)"};
    if (!bytes && size) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, j.file, "no bytes");
    cJSON* root = akp_json_parse(&j, bytes ? (const char*)bytes : "", size);
    if (root) read_scene(&j, root, out_scene);
    if (root && !j.failed) read_render(&j, root, name, out_scene);
    cJSON_Delete(root);
    if (j.failed) {
        ak_particles_scene_free(out_scene);
        return akp_json_diag(&j, AK_ERR_PARSE, out_diag);
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_particles_scene_load_file(const char* path, ak_particles_scene* out_scene, ak_diag* out_diag) {
    if (!out_scene || !path) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, path ? path : "(scene)", "no path or scene");
    memset(out_scene, 0, sizeof *out_scene);
    akp_json j = {.file = path};
    size_t size = 0;
    char* text = akp_json_read_file(&j, path, 0, &size);
    if (!text) return akp_json_diag(&j, AK_ERR_IO, out_diag);
    ak_result r = ak_particles_scene_load_bytes(text, size, path, out_scene, out_diag);
    free(text);
    return r;
}

ak_result ak_particles_scene_preset(const char* name, ak_particles_scene* out_scene, ak_diag* out_diag) {
    if (!out_scene || !name) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "preset", "no name or scene");
    if (!preset_fill(name, out_scene)) {
        const bool known = preset_known(name);
        ak_particles_scene_free(out_scene);
        if (known) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, name, "out of memory");
        return akp_diag_set(out_diag, AK_ERR_NOT_FOUND, name,
                            "unknown preset (allowed: " AK_PARTICLES_SCENE_PRESETS ")");
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

void ak_particles_scene_free(ak_particles_scene* s) {
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
