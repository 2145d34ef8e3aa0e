/* animkit view: the simulations it runs live (view_sim plug-ins). `animkit view KIND:SPEC`
 * picks one: particles:SCENE.json, particles:preset:NAME, boids[:SCENE.json], boids:preset:NAME,
 * cloth:SCENE.json, cloth:preset:NAME, terrain[:preset:NAME] (view_terrain.c), rigid[:SCENE.json],
 * rigid:preset:NAME (view_rigid.c). Each reuses its command's scene
 * parser and drawing (particles_run.c, boids_run.c, cloth_run.c), so the viewer shows what the
 * command renders. */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "boids_run.h"
#include "cloth_run.h"
#include "particles_run.h"
#include "view_app.h"

const char* const view_sim_kinds = "particles, boids, cloth, terrain, crowd, rigid";

#define MAX_STEPS_PER_FRAME 64
#define WIND_STEP 0.5f

/* A library scene loader's message into err. */
static void diag_copy(const ak_diag* d, char* err, size_t err_size) {
    if (err && err_size) snprintf(err, err_size, "%s", d->message);
}

/* Pixel radius of a sphere (centre c, radius r) as the camera sees it; false when behind. */
static bool project_sphere(const ak_raster_camera* cam, int w, int h, ak_vec3 c, float r, ak_vec3* px, float* pr) {
    const float* v = cam->view.m;
    ak_vec3 up = ak_vec3_make(v[1], v[5], v[9]);
    ak_vec3 top;
    if (!ak_raster_camera_project(cam, w, h, c, px) ||
        !ak_raster_camera_project(cam, w, h, ak_vec3_madd(c, up, r), &top))
        return false;
    *pr = hypotf(top.x - px->x, top.y - px->y);
    return true;
}

/* True when the cursor (x, y) is on the sphere (c, r) and it is nearer than *best (which it
 * then becomes): the grab test the simulations run over their spheres. */
static bool sphere_under_cursor(const ak_raster_camera* cam, int w, int h, float x, float y, ak_vec3 c, float r,
                                float* best) {
    ak_vec3 px;
    float pr;
    if (!project_sphere(cam, w, h, c, r, &px, &pr)) return false;
    if (!(hypotf(px.x - x, px.y - y) <= pr && px.z < *best)) return false;
    *best = px.z;
    return true;
}

/* Advance a simulation of fixed step sdt by a frame of dt: steps while the owed time covers
 * one (at most MAX_STEPS_PER_FRAME), dropping the debt when it falls behind. step_once returns
 * false on failure, which sets *failed and stops. */
static void run_steps(double* carry, bool* failed, float dt, float sdt, bool (*step_once)(void* state), void* state) {
    if (*failed) return;
    *carry += (double)dt;
    for (int n = 0; *carry >= 0.999999 * (double)sdt && n < MAX_STEPS_PER_FRAME; ++n) {
        if (!step_once(state)) {
            *failed = true;
            return;
        }
        *carry -= (double)sdt;
    }
    if (*carry > (double)sdt) *carry = 0.0; /* fell behind: drop the debt */
}

/* Grow the box [lo, hi] to hold [blo, bhi]. */
static void box_union(ak_vec3* lo, ak_vec3* hi, ak_vec3 blo, ak_vec3 bhi) {
    *lo = ak_vec3_min(*lo, blo);
    *hi = ak_vec3_max(*hi, bhi);
}

/* The wind keys (a/d: -x/+x, q/e: -z/+z, WIND_STEP m/s each): add to *wind and say the new
 * wind in msg; false for any other key. */
static bool wind_key(int key, ak_vec3* wind, char* msg, size_t msg_size) {
    ak_vec3 d;
    switch (key) {
    case 'a': d = ak_vec3_make(-WIND_STEP, 0, 0); break;
    case 'd': d = ak_vec3_make(WIND_STEP, 0, 0); break;
    case 'q': d = ak_vec3_make(0, 0, -WIND_STEP); break;
    case 'e': d = ak_vec3_make(0, 0, WIND_STEP); break;
    default: return false;
    }
    *wind = ak_vec3_add(*wind, d);
    snprintf(msg, msg_size, "wind %.2g %.2g %.2g m/s", (double)wind->x, (double)wind->y, (double)wind->z);
    return true;
}

/* An init that fails: the message into err, the half-built state destroyed; returns rc. */
static int init_fail(void (*destroy)(void*), void* state, int rc, char* err, size_t err_size, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;
static int init_fail(void (*destroy)(void*), void* state, int rc, char* err, size_t err_size, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_size, fmt, ap);
    va_end(ap);
    destroy(state);
    return rc;
}

/* ---- particles ---------------------------------------------------------------------------- */

typedef struct psim {
    ak_particles_scene scene;
    ak_particle_sphere* spheres0; /* the spheres as loaded (reset puts them back) */
    particles_character ch;
    bool use_char, char_ready;
    particles_run run;
    bool run_ready, failed;
    particles_shapes sh;
    ak_vec4* colours;
    particles_sprite_renderer sprites;
    long step_index;
    double carry; /* simulated time owed to the next step */
    ak_vec3 lo, hi;
    int grabbed;
    uint64_t seed;
    uint32_t threads;
} psim;

static bool psim_sky(void* state, ak_vec4* top, ak_vec4* bottom) {
    return particles_dark_sky(&((const psim*)state)->scene, top, bottom);
}

static void psim_destroy(void* state) {
    psim* p = state;
    if (!p) return;
    particles_run_free(&p->run);
    particles_shapes_free(&p->sh);
    if (p->char_ready) particles_character_free(&p->ch);
    free(p->spheres0);
    free(p->colours);
    particles_sprites_free(&p->sprites);
    ak_particles_scene_free(&p->scene);
    free(p);
}

/* Back to the loaded state: spheres, wind (the run copies the scene's world), time 0. */
static int psim_restart(psim* p) {
    for (size_t k = 0; k < p->scene.world.spheres.count; ++k) p->scene.spheres[k] = p->spheres0[k];
    if (p->run_ready) particles_run_free(&p->run);
    memset(&p->run, 0, sizeof p->run);
    p->run_ready = false;
    p->step_index = 0;
    p->carry = 0.0;
    p->failed = false;
    if (p->use_char && particles_character_pose(&p->ch, 0.0f, 0.0f) != AK_OK)
        return cli_fail("view", "cannot pose the character");
    int rc = particles_run_init(&p->run, &p->scene, p->use_char ? &p->ch : NULL, p->seed, p->threads);
    p->run_ready = true;
    if (rc) return rc;
    particles_shapes_free(&p->sh);
    return particles_shapes_build(&p->sh, &p->scene) ? CLI_OK : cli_fail("view", "out of memory");
}

/* The box the camera frames: colliders, emitters, and where the particles go in a dry run of
 * the first 2 seconds (as `animkit particles -o` frames its whole run); the floor plane. */
static int psim_bounds_run(psim* p) {
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    const ak_particles_scene* s = &p->scene;
    for (size_t k = 0; k < s->world.spheres.count; ++k) {
        const ak_particle_sphere* sp = &s->world.spheres.ptr[k];
        particles_bounds_add(&lo, &hi, ak_vec3_sub(sp->center, ak_vec3_splat(sp->radius)));
        particles_bounds_add(&lo, &hi, ak_vec3_add(sp->center, ak_vec3_splat(sp->radius)));
    }
    for (size_t k = 0; k < s->world.boxes.count; ++k) {
        particles_bounds_add(&lo, &hi, s->world.boxes.ptr[k].min);
        particles_bounds_add(&lo, &hi, s->world.boxes.ptr[k].max);
    }
    for (size_t k = 0; k < s->emitter_count; ++k) particles_bounds_add(&lo, &hi, s->emitters[k].center);
    int rc = psim_restart(p);
    long steps = (long)ceilf(2.0f / s->dt);
    if (steps > 400) steps = 400;
    for (long k = 0; rc == CLI_OK && k <= steps; ++k) {
        if (k > 0) rc = particles_run_step(&p->run, (int)k - 1);
        if (k % 10 && k != steps) continue;
        ak_particles_state st = ak_particles_get_state(p->run.ps);
        for (size_t i = 0; i < st.count; i += 1 + st.count / 4000) particles_bounds_add(&lo, &hi, st.position[i]);
        if (p->use_char)
            for (size_t v = 0; v < p->ch.vertex_count; v += 7) particles_bounds_add(&lo, &hi, p->ch.positions[v]);
    }
    if (rc) return rc;
    if (!(lo.x <= hi.x)) lo = ak_vec3_splat(-1), hi = ak_vec3_splat(1);
    for (size_t k = 0; k < s->world.planes.count; ++k) {
        ak_vec3 n = ak_vec3_normalize(s->world.planes.ptr[k].normal);
        if (n.y > 0.99f) lo.y = fminf(lo.y, s->world.planes.ptr[k].d / n.y);
    }
    p->lo = lo;
    p->hi = hi;
    return psim_restart(p);
}

static int psim_init(void** state, const char* spec, const view_sim_opts* o, char* err, size_t err_size) {
    psim* p = calloc(1, sizeof *p);
    if (!p) {
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    p->grabbed = -1;
    p->seed = o->has_seed ? o->seed : 1; /* `animkit particles` seeds its runs with 1 */
    p->threads = o->threads > 0 ? (uint32_t)o->threads : 1;
    int rc = CLI_OK;
    if (strncmp(spec, "preset:", 7) == 0) {
        const char* name = spec + 7;
        if (!particles_preset_known(name))
            return init_fail(psim_destroy, p, CLI_BAD_USAGE, err, err_size,
                             "particles:preset:%s: the presets are " AK_PARTICLES_SCENE_PRESETS, name);
        ak_diag diag;
        if (ak_particles_scene_preset(name, &p->scene, &diag) != AK_OK)
            return init_fail(psim_destroy, p, CLI_BAD_INPUT, err, err_size, "%s", diag.message);
        p->use_char = strcmp(name, "character") == 0;
    } else if (!spec[0]) {
        return init_fail(psim_destroy, p, CLI_BAD_USAGE, err, err_size,
                         "particles: give a scene file (particles:SCENE.json) or a preset (particles:preset:NAME)");
    } else {
        ak_diag diag;
        if (ak_particles_scene_load_file(spec, &p->scene, &diag) != AK_OK) {
            diag_copy(&diag, err, err_size);
            psim_destroy(p);
            return CLI_BAD_INPUT;
        }
    }
    size_t ns = p->scene.world.spheres.count;
    p->spheres0 = calloc(ns + 1, sizeof *p->spheres0);
    p->colours = calloc((size_t)p->scene.capacity + 1, sizeof(ak_vec4));
    if (!p->spheres0 || !p->colours)
        return init_fail(psim_destroy, p, CLI_BAD_INPUT, err, err_size, "out of memory");
    if (ns) memcpy(p->spheres0, p->scene.spheres, ns * sizeof *p->spheres0);
    if (p->use_char) {
        particles_character_init(&p->ch, &rc);
        p->char_ready = true; /* freed at the end whatever init made */
    }
    if (rc == CLI_OK) rc = psim_bounds_run(p);
    if (rc == CLI_OK) rc = particles_sprites_init(&p->sprites, &p->scene, "view");
    if (rc)
        return init_fail(psim_destroy, p, CLI_BAD_INPUT, err, err_size, "cannot start the particle simulation");
    *state = p;
    return CLI_OK;
}

static bool psim_step_once(void* state) {
    psim* p = state;
    if (particles_run_step(&p->run, (int)p->step_index) != CLI_OK) return false;
    ++p->step_index;
    return true;
}

static void psim_step(void* state, float dt) {
    psim* p = state;
    run_steps(&p->carry, &p->failed, dt, p->scene.dt, psim_step_once, p);
}

static void psim_reset(void* state) {
    psim* p = state;
    if (psim_restart(p) != CLI_OK) p->failed = true;
}

static bool psim_failed(void* state) { return ((const psim*)state)->failed; }

static size_t psim_meshes(void* state, ak_raster_mesh* out, size_t cap) {
    psim* p = state;
    size_t n = 0;
    if (p->sh.icount && n < cap)
        out[n++] = (ak_raster_mesh){.positions = {p->sh.pos, p->sh.vcount},
                                    .normals = {p->sh.nrm, p->sh.vcount},
                                    .indices = {p->sh.idx, p->sh.icount},
                                    .material = {.color = {0.75f, 0.72f, 0.68f, 1}}};
    if (p->use_char && n < cap)
        out[n++] = (ak_raster_mesh){.positions = {p->ch.positions, p->ch.vertex_count},
                                    .indices = {p->ch.indices, p->ch.index_count},
                                    .material = {.color = {0.80f, 0.74f, 0.68f, 1}},
                                    .shading = AK_SHADING_FLAT};
    return n;
}

static ak_result psim_draw(void* state, ak_raster* ras, const ak_raster_camera* cam, int w, int h) {
    psim* p = state;
    if (p->sprites.ready) return particles_draw_sprites(ras, cam, &p->scene, &p->sprites, p->run.ps);
    return particles_draw_points(ras, cam, w, h, ak_vec3_scale(ak_vec3_add(p->lo, p->hi), 0.5f), p->run.ps, p->colours);
}

static void psim_bounds(void* state, ak_vec3* lo, ak_vec3* hi) {
    const psim* p = state;
    box_union(lo, hi, p->lo, p->hi);
}

static bool psim_key(void* state, int key, char* msg, size_t msg_size) {
    psim* p = state;
    return wind_key(key, &p->run.lib.world.wind, msg, msg_size);
}

static bool psim_grab(void* state, const ak_raster_camera* cam, int w, int h, float x, float y, ak_vec3* anchor) {
    psim* p = state;
    p->grabbed = -1;
    float best = INFINITY;
    for (size_t k = 0; k < p->scene.world.spheres.count; ++k) {
        const ak_particle_sphere* s = &p->scene.spheres[k];
        if (sphere_under_cursor(cam, w, h, x, y, s->center, s->radius, &best)) p->grabbed = (int)k;
    }
    if (p->grabbed < 0) return false;
    *anchor = p->scene.spheres[p->grabbed].center;
    return true;
}

static void psim_drag(void* state, ak_vec3 delta) {
    psim* p = state;
    if (p->grabbed < 0 || !ak_vec3_is_finite(delta)) return;
    ak_particle_sphere* s = &p->scene.spheres[p->grabbed];
    s->center = ak_vec3_add(s->center, delta);
    particles_shapes_free(&p->sh);
    if (!particles_shapes_build(&p->sh, &p->scene)) {
        particles_shapes_free(&p->sh);
        memset(&p->sh, 0, sizeof p->sh);
    }
}

static void psim_status(void* state, char* out, size_t n) {
    psim* p = state;
    ak_vec3 w = p->run.lib.world.wind;
    snprintf(out, n, "t %.2fs, %zu particles, wind %.2g %.2g %.2g%s", ak_particles_time(p->run.ps),
             ak_particles_get_state(p->run.ps).count, (double)w.x, (double)w.y, (double)w.z,
             p->failed ? ", stopped (step failed)" : "");
}

static const view_help_entry psim_keys[] = {
    {"r", "restart the simulation (also tab)"},
    {"right", "one frame of simulation, paused"},
    {"a", "wind -x (0.5 m/s)"},
    {"d", "wind +x"},
    {"q", "wind -z"},
    {"e", "wind +z"},
};

static const view_sim particles_sim = {
    .name = "particles",
    .init = psim_init,
    .step = psim_step,
    .reset = psim_reset,
    .meshes = psim_meshes,
    .draw = psim_draw,
    .bounds = psim_bounds,
    .sky = psim_sky,
    .key = psim_key,
    .grab = psim_grab,
    .drag = psim_drag,
    .status = psim_status,
    .destroy = psim_destroy,
    .failed = psim_failed,
    .keys = psim_keys,
    .key_count = sizeof psim_keys / sizeof psim_keys[0],
};

/* ---- boids ------------------------------------------------------------------------------- */

typedef struct bsim {
    ak_boids_scene sc;
    ak_boids_obstacle* obstacles0; /* as loaded (reset puts them back) */
    boids_run run;
    boids_shapes sh;
    long step_index;
    double carry;
    bool failed;
    const char* file;
    ak_vec3 lo, hi;
    float extent;
    int grabbed;
    uint32_t threads;
} bsim;

static void bsim_destroy(void* state) {
    bsim* b = state;
    if (!b) return;
    boids_run_free(&b->run);
    boids_shapes_free(&b->sh);
    free(b->obstacles0);
    ak_boids_scene_free(&b->sc);
    free(b);
}

static int bsim_restart(bsim* b) {
    uint32_t no = b->sc.params.obstacle_count;
    if (no) memcpy(b->sc.obstacles, b->obstacles0, no * sizeof *b->obstacles0);
    boids_run_free(&b->run);
    b->step_index = 0;
    b->carry = 0.0;
    b->failed = false;
    int rc = boids_run_init(&b->run, &b->sc, "view", b->file, b->threads, false);
    if (rc) return rc;
    return boids_shapes_obstacles(&b->sh, &b->sc.params, b->extent) ? CLI_OK : cli_fail("view", "out of memory");
}

static int bsim_init(void** state, const char* spec, const view_sim_opts* o, char* err, size_t err_size) {
    bsim* b = calloc(1, sizeof *b);
    if (!b) {
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    b->grabbed = -1;
    b->threads = o->threads > 0 ? (uint32_t)o->threads : 1;
    b->file = spec[0] ? spec : "boids (default scene)";
    ak_boids_scene_defaults(&b->sc);
    if (strncmp(spec, "preset:", 7) == 0) {
        ak_diag diag;
        const ak_result res = ak_boids_scene_preset(spec + 7, &b->sc, &diag);
        if (res == AK_ERR_NOT_FOUND)
            return init_fail(bsim_destroy, b, CLI_BAD_USAGE, err, err_size,
                             "boids:%s: the presets are " AK_BOIDS_SCENE_PRESETS, spec);
        if (res != AK_OK) return init_fail(bsim_destroy, b, CLI_BAD_INPUT, err, err_size, "out of memory");
    } else if (spec[0]) {
        ak_diag diag;
        if (ak_boids_scene_load_file(spec, &b->sc, &diag) != AK_OK) {
            diag_copy(&diag, err, err_size);
            bsim_destroy(b);
            return CLI_BAD_INPUT;
        }
    }
    if (o->has_seed) b->sc.seed = (long)(o->seed % 2147483648u); /* the scene's seed is 0..2^31-1 */
    /* the box the command's camera looks at, down to its ground */
    const ak_boids_params* prm = &b->sc.params;
    b->lo = prm->bounds_min;
    b->hi = prm->bounds_max;
    b->extent = 0.5f * ak_vec3_length(ak_vec3_sub(b->hi, b->lo));
    float ground = prm->planar ? -0.5f * b->sc.shape_size - 0.3f : b->lo.y - 0.05f * b->extent;
    for (uint32_t k = 0; k < prm->obstacle_count; ++k)
        if (boids_is_floor(&prm->obstacles[k])) ground = prm->obstacles[k].center.y;
    if (prm->planar) b->lo.y = b->hi.y = 0.0f;
    b->lo.y = ak_minf(b->lo.y, ground);
    size_t n = b->sc.agent_count > 0 ? b->sc.agent_count : b->sc.count;
    b->obstacles0 = calloc(prm->obstacle_count + 1u, sizeof *b->obstacles0);
    if (!b->obstacles0 || !boids_shapes_init(&b->sh, &b->sc, n, b->extent))
        return init_fail(bsim_destroy, b, CLI_BAD_INPUT, err, err_size, "out of memory");
    if (prm->obstacle_count) memcpy(b->obstacles0, b->sc.obstacles, prm->obstacle_count * sizeof *b->obstacles0);
    if (bsim_restart(b))
        return init_fail(bsim_destroy, b, CLI_BAD_INPUT, err, err_size, "cannot start the flock");
    *state = b;
    return CLI_OK;
}

static bool bsim_step_once(void* state) {
    bsim* b = state;
    ak_result r = boids_run_step(&b->run, b->step_index);
    if (r != AK_OK) {
        cli_fail("view", "%s: step %ld: %s", b->file ? b->file : "boids", b->step_index + 1, ak_result_string(r));
        return false;
    }
    ++b->step_index;
    return true;
}

static void bsim_step(void* state, float dt) {
    bsim* b = state;
    run_steps(&b->carry, &b->failed, dt, b->sc.dt, bsim_step_once, b);
}

static void bsim_reset(void* state) {
    bsim* b = state;
    if (bsim_restart(b) != CLI_OK) b->failed = true;
}

static bool bsim_failed(void* state) { return ((const bsim*)state)->failed; }

static size_t bsim_meshes(void* state, ak_raster_mesh* out, size_t cap) {
    bsim* b = state;
    ak_raster_mesh birds, obs;
    boids_shapes_update(&b->sh, &b->sc, &b->run, (float)b->step_index * b->sc.dt, &birds, &obs);
    size_t n = 0;
    if (n < cap && b->run.agent_count) out[n++] = birds;
    if (n < cap && b->sh.otri) out[n++] = obs;
    return n;
}

static void bsim_bounds(void* state, ak_vec3* lo, ak_vec3* hi) {
    const bsim* b = state;
    box_union(lo, hi, b->lo, b->hi);
}

static bool bsim_grab(void* state, const ak_raster_camera* cam, int w, int h, float x, float y, ak_vec3* anchor) {
    bsim* b = state;
    b->grabbed = -1;
    float best = INFINITY;
    for (uint32_t k = 0; k < b->sc.params.obstacle_count; ++k) {
        const ak_boids_obstacle* o = &b->sc.obstacles[k];
        if (o->kind == AK_BOIDS_SPHERE && sphere_under_cursor(cam, w, h, x, y, o->center, o->radius, &best))
            b->grabbed = (int)k;
    }
    if (b->grabbed < 0) return false;
    *anchor = b->sc.obstacles[b->grabbed].center;
    return true;
}

static void bsim_drag(void* state, ak_vec3 delta) {
    bsim* b = state;
    if (b->grabbed < 0 || !ak_vec3_is_finite(delta)) return;
    ak_boids_obstacle* o = &b->sc.obstacles[b->grabbed];
    o->center = ak_vec3_add(o->center, delta);
    if (b->sc.params.planar) o->center.y = 0.0f; /* 2D flocks cut obstacles at y = 0 */
    if (!boids_shapes_obstacles(&b->sh, &b->sc.params, b->extent)) b->sh.overt = b->sh.otri = 0;
}

static void bsim_status(void* state, char* out, size_t n) {
    bsim* b = state;
    snprintf(out, n, "t %.2fs, %zu agents, order %.3f%s", (double)b->step_index * (double)b->sc.dt, b->run.agent_count,
             (double)ak_boids_order((ak_vec3_cspan){b->run.velocities, b->run.agent_count}), b->failed ? ", stopped (step failed)" : "");
}

static const view_help_entry bsim_keys[] = {
    {"r", "restart the flock (also tab)"},
    {"right", "one frame of simulation, paused"},
};

static const view_sim boids_sim = {
    .name = "boids",
    .init = bsim_init,
    .step = bsim_step,
    .reset = bsim_reset,
    .meshes = bsim_meshes,
    .bounds = bsim_bounds,
    .grab = bsim_grab,
    .drag = bsim_drag,
    .status = bsim_status,
    .destroy = bsim_destroy,
    .failed = bsim_failed,
    .keys = bsim_keys,
    .key_count = sizeof bsim_keys / sizeof bsim_keys[0],
};

/* ---- cloth -------------------------------------------------------------------------------- */

typedef struct csim {
    ak_cloth_scene sc;
    bool sc_ready;
    char name[64];
    ak_cloth_sphere* spheres0; /* as loaded (reset puts them back, and the wind) */
    ak_vec3 wind0;
    cloth_run run;
    cloth_prop* props;         /* spheres, then the scene's capsules */
    size_t prop_count;
    double carry;
    bool failed;
    ak_vec3 lo, hi;
    int grabbed;
} csim;

static void csim_destroy(void* state) {
    csim* c = state;
    if (!c) return;
    cloth_run_free(&c->run);
    free(c->props);
    free(c->spheres0);
    if (c->sc_ready) ak_cloth_scene_free(&c->sc);
    free(c);
}

static void csim_props(csim* c) {
    for (size_t k = 0; k < c->prop_count; ++k) {
        if (k < c->sc.sphere_count) {
            cloth_prop_build(&c->props[k], c->sc.spheres[k].center, c->sc.spheres[k].center, c->sc.spheres[k].radius);
        } else {
            const ak_cloth_capsule* cp = &c->sc.capsules[k - c->sc.sphere_count];
            cloth_prop_build(&c->props[k], cp->a, cp->b, cp->radius);
        }
    }
}

static int csim_restart(csim* c) {
    if (c->sc.sphere_count) memcpy(c->sc.spheres, c->spheres0, c->sc.sphere_count * sizeof *c->spheres0);
    c->sc.wind = c->wind0;
    cloth_run_free(&c->run);
    c->carry = 0.0;
    c->failed = false;
    csim_props(c);
    return cloth_run_init(&c->run, &c->sc, "view", c->name);
}

static int csim_init(void** state, const char* spec, const view_sim_opts* o, char* err, size_t err_size) {
    csim* c = calloc(1, sizeof *c);
    if (!c) {
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    c->grabbed = -1;
    snprintf(c->name, sizeof c->name, "%s", spec);
    if (strncmp(spec, "preset:", 7) == 0) {
        c->sc_ready = true;
        ak_diag diag;
        if (ak_cloth_scene_preset(spec + 7, &c->sc, &diag) != AK_OK)
            return init_fail(csim_destroy, c, CLI_BAD_USAGE, err, err_size,
                             "cloth:%s: the presets are flag, curtain, drape, cape", spec);
        snprintf(c->name, sizeof c->name, "%s", spec + 7);
    } else if (!spec[0]) {
        return init_fail(csim_destroy, c, CLI_BAD_USAGE, err, err_size,
                         "cloth: give a scene file (cloth:SCENE.json) or a preset (cloth:preset:NAME)");
    } else {
        ak_diag diag;
        const bool ok = ak_cloth_scene_load_file(spec, &c->sc, &diag) == AK_OK;
        c->sc_ready = ok;
        if (!ok) {
            diag_copy(&diag, err, err_size);
            csim_destroy(c);
            return CLI_BAD_INPUT;
        }
    }
    c->wind0 = c->sc.wind;
    if (o->threads > 0) c->sc.thread_count = o->threads; /* the cloth has no random numbers: --seed does nothing */
    c->prop_count = c->sc.sphere_count + c->sc.capsule_count;
    if (c->prop_count > CLI_MAX_EXTRA - 1) c->prop_count = CLI_MAX_EXTRA - 1;
    c->spheres0 = calloc(c->sc.sphere_count + 1, sizeof *c->spheres0);
    c->props = calloc(c->prop_count + 1, sizeof *c->props);
    if (!c->spheres0 || !c->props)
        return init_fail(csim_destroy, c, CLI_BAD_INPUT, err, err_size, "out of memory");
    if (c->sc.sphere_count) memcpy(c->spheres0, c->sc.spheres, c->sc.sphere_count * sizeof *c->spheres0);
    if (csim_restart(c))
        return init_fail(csim_destroy, c, CLI_BAD_INPUT, err, err_size, "cannot start the cloth");
    cloth_run_bounds(&c->run, &c->lo, &c->hi);
    *state = c;
    return CLI_OK;
}

static bool csim_step_once(void* state) {
    csim* c = state;
    return cloth_run_step(&c->run, "view", c->name) == CLI_OK;
}

static void csim_step(void* state, float dt) {
    csim* c = state;
    run_steps(&c->carry, &c->failed, dt, c->sc.dt, csim_step_once, c);
}

static void csim_reset(void* state) {
    csim* c = state;
    if (csim_restart(c) != CLI_OK) c->failed = true;
}

static bool csim_failed(void* state) { return ((const csim*)state)->failed; }

/* The cloth, the collider props and the character's posed meshes, as `animkit cloth` draws them. */
static size_t csim_meshes(void* state, ak_raster_mesh* out, size_t cap) {
    csim* c = state;
    size_t n = 0;
    if (n < cap && c->run.cloth)
        out[n++] = (ak_raster_mesh){.positions = {c->run.x, c->run.n}, .normals = {c->run.nrm, c->run.n},
                                    .indices = ak_cloth_indices(c->run.cloth),
                                    .material = {.color = {0.72f, 0.16f, 0.18f, 1}, .specular = 0.1f}};
    for (size_t k = 0; k < c->prop_count && n < cap; ++k)
        out[n++] = (ak_raster_mesh){.positions = {c->props[k].pos, PROP_VERTS}, .normals = {c->props[k].nrm, PROP_VERTS},
                                    .indices = {c->props[k].idx, PROP_TRIS * 3},
                                    .material = {.color = {0.55f, 0.62f, 0.72f, 1}}};
    const ak_scene* s = c->run.ch.scene;
    for (size_t m = 0; s && m < s->mesh_count && n < cap; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        if (!mesh || !mesh->triangle_count) continue;
        out[n++] = (ak_raster_mesh){.positions = {c->run.ch.poser.positions[m], mesh->vertex_count},
                                    .normals = {c->run.ch.poser.normals[m], mesh->vertex_count},
                                    .indices = {mesh->indices, mesh->triangle_count * 3},
                                    .material = {.color = {0.80f, 0.74f, 0.68f, 1}}};
    }
    return n;
}

static void csim_bounds(void* state, ak_vec3* lo, ak_vec3* hi) {
    const csim* c = state;
    box_union(lo, hi, c->lo, c->hi);
}

static bool csim_key(void* state, int key, char* msg, size_t msg_size) {
    csim* c = state;
    return wind_key(key, &c->sc.wind, msg, msg_size);
}

static bool csim_grab(void* state, const ak_raster_camera* cam, int w, int h, float x, float y, ak_vec3* anchor) {
    csim* c = state;
    c->grabbed = -1;
    float best = INFINITY;
    for (size_t k = 0; k < c->sc.sphere_count; ++k) {
        if (sphere_under_cursor(cam, w, h, x, y, c->sc.spheres[k].center, c->sc.spheres[k].radius, &best))
            c->grabbed = (int)k;
    }
    if (c->grabbed < 0) return false;
    *anchor = c->sc.spheres[c->grabbed].center;
    return true;
}

static void csim_drag(void* state, ak_vec3 delta) {
    csim* c = state;
    if (c->grabbed < 0 || !ak_vec3_is_finite(delta)) return;
    ak_cloth_sphere* s = &c->sc.spheres[c->grabbed];
    s->center = ak_vec3_add(s->center, delta);
    if ((size_t)c->grabbed < c->prop_count) cloth_prop_build(&c->props[c->grabbed], s->center, s->center, s->radius);
}

static void csim_status(void* state, char* out, size_t n) {
    csim* c = state;
    ak_vec3 w = c->sc.wind;
    snprintf(out, n, "t %.2fs, %zu particles, wind %.2g %.2g %.2g%s", (double)c->run.time, c->run.n, (double)w.x,
             (double)w.y, (double)w.z, c->failed ? ", stopped (step failed)" : "");
}

static const view_help_entry csim_keys[] = {
    {"r", "restart the cloth (also tab)"},
    {"right", "one frame of simulation, paused"},
    {"a", "wind -x (0.5 m/s)"},
    {"d", "wind +x"},
    {"q", "wind -z"},
    {"e", "wind +z"},
};

static const view_sim cloth_sim = {
    .name = "cloth",
    .init = csim_init,
    .step = csim_step,
    .reset = csim_reset,
    .meshes = csim_meshes,
    .bounds = csim_bounds,
    .key = csim_key,
    .grab = csim_grab,
    .drag = csim_drag,
    .status = csim_status,
    .destroy = csim_destroy,
    .failed = csim_failed,
    .keys = csim_keys,
    .key_count = sizeof csim_keys / sizeof csim_keys[0],
};

/* ---- the table ---------------------------------------------------------------------------- */

static const struct {
    const char* kind;
    const view_sim* sim;
} sims[] = {
    {"particles", &particles_sim},
    {"boids", &boids_sim},
    {"cloth", &cloth_sim},
    {"terrain", &view_terrain_sim},
    {"crowd", &view_crowd_sim},
    {"rigid", &view_rigid_sim},
};

const view_sim* view_sim_at(size_t index) { return index < sizeof sims / sizeof sims[0] ? sims[index].sim : NULL; }

const view_sim* view_sim_find(const char* arg, const char** spec) {
    for (size_t k = 0; k < sizeof sims / sizeof sims[0]; ++k) {
        size_t n = strlen(sims[k].kind);
        if (strncmp(arg, sims[k].kind, n) == 0 && (arg[n] == ':' || arg[n] == '\0')) {
            *spec = arg[n] ? arg + n + 1 : "";
            return sims[k].sim;
        }
    }
    return NULL;
}
