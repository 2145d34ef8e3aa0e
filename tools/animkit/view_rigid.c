/* animkit view: rigid bodies live (include/animkit/rigid.h). `animkit view rigid` runs the
 * ragdoll preset, `rigid:preset:NAME` another preset, `rigid:SCENE.json` a scene file, stepped
 * as `animkit rigid` steps them (ak_rigid_scene_run). The right mouse button throws a sphere
 * from the camera through the pixel: the scene gets THROW_COUNT spare spheres, parked asleep
 * far below the ground until thrown (a model is immutable, so bodies cannot be added later);
 * the oldest is thrown again once all are in use. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "view_app.h"

#define THROW_COUNT 8
#define THROW_RADIUS 0.15f
#define THROW_SPEED 12.0f /* m/s */
#define PARK_SLEEP 1e30f  /* a parked sphere's sleep timer: asleep whatever sleep_time is */
#define MAX_STEPS_PER_FRAME 64

typedef struct rsim {
    ak_rigid_scene sc;
    bool sc_ready;
    char name[64];
    size_t user_count; /* the scene's bodies; the spare spheres follow */
    ak_rigid_scene_run run;
    bool failed;
    double carry;
    size_t thrown, next; /* spheres thrown since the restart; the next one to throw */
    bool live[THROW_COUNT];
    ak_vec3 *mp, *mn; /* the bodies' meshes, world space (live bodies only) */
    uint32_t* mi;
    size_t mv_cap, mi_cap, mv, mic;
    ak_vec3 lo, hi;
} rsim;

static void rsim_destroy(void* state) {
    rsim* r = state;
    if (!r) return;
    ak_rigid_scene_run_free(&r->run);
    if (r->sc_ready) ak_rigid_scene_free(&r->sc);
    free(r->mp), free(r->mn), free(r->mi);
    free(r);
}

static ak_vec3 park_position(size_t k) {
    return ak_vec3_make(1000.0f + 3.0f * (float)k, -1000.0f, 0.0f);
}

/* The run from the scene; the spare spheres parked asleep. */
static int rsim_restart(rsim* r) {
    ak_rigid_scene_run_free(&r->run);
    r->carry = 0.0;
    r->failed = false;
    r->thrown = r->next = 0;
    memset(r->live, 0, sizeof r->live);
    ak_diag diag;
    if (ak_rigid_scene_run_init(&r->run, &r->sc, r->name, &diag) != AK_OK) {
        fprintf(stderr, "animkit view: %s\n", diag.message);
        return CLI_BAD_INPUT;
    }
    float* timers = r->run.job.sleep_timers.ptr;
    for (size_t k = 0; k < THROW_COUNT && timers; ++k) timers[r->user_count + k] = PARK_SLEEP;
    return CLI_OK;
}

/* The world mesh of every body but the planes and the parked spheres. */
static void rsim_mesh(rsim* r) {
    r->mv = r->mic = 0;
    const ak_rigid_model* m = r->run.model;
    for (size_t i = 0; m && i < r->run.body_count; ++i) {
        if (i >= r->user_count && !r->live[i - r->user_count]) continue;
        ak_rigid_body_desc d = ak_rigid_body_get_desc(m, i);
        if (d.shape.type == AK_RIGID_PLANE) continue;
        size_t nv, ni; /* each shape as itself (hull faces, compound children, mesh triangles) */
        ak_rigid_body_mesh_size(m, i, &nv, &ni);
        if (r->mv + nv > r->mv_cap || r->mic + ni > r->mi_cap) break;
        if (!nv) continue;
        ak_rigid_body_mesh(m, i, 0.0f, (ak_vec3_span){r->mp + r->mv, nv},
                           (ak_vec3_span){r->mn + r->mv, nv}, (ak_u32_span){r->mi + r->mic, ni});
        const ak_quat q = ak_quat_normalize(r->run.orientations[i]);
        for (size_t v = r->mv; v < r->mv + nv; ++v) {
            r->mp[v] = ak_vec3_add(r->run.positions[i], ak_quat_rotate(q, r->mp[v]));
            r->mn[v] = ak_quat_rotate(q, r->mn[v]);
        }
        for (size_t k = r->mic; k < r->mic + ni; ++k) r->mi[k] += (uint32_t)r->mv;
        r->mv += nv, r->mic += ni;
    }
}

static int rsim_init(void** state, const char* spec, const view_sim_opts* o, char* err,
                     size_t err_size) {
    rsim* r = calloc(1, sizeof *r);
    if (!r) {
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    ak_diag diag;
    ak_rigid_scene_defaults(&r->sc);
    r->sc_ready = true;
    const char* preset = !spec[0] ? "ragdoll" : strncmp(spec, "preset:", 7) == 0 ? spec + 7 : NULL;
    if (preset) {
        snprintf(r->name, sizeof r->name, "%s", preset);
        if (ak_rigid_scene_preset(preset, &r->sc, &diag) != AK_OK) {
            snprintf(err, err_size, "rigid:preset:%s: the presets are %s", preset,
                     AK_RIGID_SCENE_PRESETS);
            rsim_destroy(r);
            return CLI_BAD_USAGE;
        }
    } else {
        snprintf(r->name, sizeof r->name, "%s", spec);
        if (ak_rigid_scene_load_file(spec, &r->sc, &diag) != AK_OK) {
            snprintf(err, err_size, "%s", diag.message);
            rsim_destroy(r);
            return CLI_BAD_INPUT;
        }
    }
    if (o->threads > 0) r->sc.thread_count = (uint32_t)o->threads;
    /* the spare spheres: sleeping needs timers, so a scene without sleep gets them with a
     * sleep time no body reaches */
    if (!r->sc.sleep) {
        r->sc.sleep = true;
        r->sc.model.sleep_time = 1e29f;
    }
    r->user_count = r->sc.body_count;
    ak_rigid_body_desc* grown =
        realloc(r->sc.bodies, (r->user_count + THROW_COUNT) * sizeof *grown);
    if (!grown) {
        snprintf(err, err_size, "out of memory");
        rsim_destroy(r);
        return CLI_BAD_INPUT;
    }
    r->sc.bodies = grown;
    for (size_t k = 0; k < THROW_COUNT; ++k)
        r->sc.bodies[r->user_count + k] =
            (ak_rigid_body_desc){.shape = {.type = AK_RIGID_SPHERE, .radius = THROW_RADIUS},
                                 .position = park_position(k),
                                 .density = 2000.0f,
                                 .restitution = 0.3f};
    r->sc.body_count = r->user_count + THROW_COUNT;
    int rc = rsim_restart(r);
    if (rc != CLI_OK) {
        snprintf(err, err_size, "%s: the scene cannot run", r->name);
        rsim_destroy(r);
        return CLI_BAD_INPUT;
    }
    /* mesh capacity: every body as drawn */
    for (size_t i = 0; i < r->run.body_count; ++i) {
        size_t nv, ni;
        ak_rigid_body_mesh_size(r->run.model, i, &nv, &ni);
        r->mv_cap += nv, r->mi_cap += ni;
    }
    r->mp = malloc((r->mv_cap + 1) * sizeof *r->mp);
    r->mn = malloc((r->mv_cap + 1) * sizeof *r->mn);
    r->mi = malloc((r->mi_cap + 1) * sizeof *r->mi);
    if (!r->mp || !r->mn || !r->mi) {
        snprintf(err, err_size, "out of memory");
        rsim_destroy(r);
        return CLI_BAD_INPUT;
    }
    /* framed on the bodies at the start (and the ground under them) */
    rsim_mesh(r);
    r->lo = ak_vec3_splat(-1.0f), r->hi = ak_vec3_splat(1.0f);
    r->lo.y = 0.0f;
    for (size_t v = 0; v < r->mv; ++v)
        r->lo = ak_vec3_min(r->lo, r->mp[v]), r->hi = ak_vec3_max(r->hi, r->mp[v]);
    *state = r;
    return CLI_OK;
}

static void rsim_step(void* state, float dt) {
    rsim* r = state;
    if (r->failed) return;
    r->carry += (double)dt;
    const double sdt = (double)r->run.job.dt;
    for (int n = 0; r->carry >= 0.999999 * sdt && n < MAX_STEPS_PER_FRAME; ++n) {
        ak_result res = ak_rigid_scene_run_step(&r->run);
        if (res != AK_OK) {
            fprintf(stderr, "animkit view: rigid %s: step %ld failed: %s\n", r->name,
                    r->run.step_index + 1, ak_result_string(res));
            r->failed = true;
            return;
        }
        r->carry -= sdt;
    }
    if (r->carry > sdt) r->carry = 0.0; /* fell behind: drop the debt */
}

static void rsim_reset(void* state) {
    rsim* r = state;
    if (rsim_restart(r) != CLI_OK) r->failed = true;
}

static bool rsim_failed(void* state) { return ((const rsim*)state)->failed; }

static size_t rsim_meshes(void* state, ak_raster_mesh* out, size_t cap) {
    rsim* r = state;
    rsim_mesh(r);
    if (!cap || !r->mv) return 0;
    out[0] = (ak_raster_mesh){.positions = {r->mp, r->mv},
                              .normals = {r->mn, r->mv},
                              .indices = {r->mi, r->mic},
                              .material = {.color = {0.80f, 0.55f, 0.25f, 1}, .specular = 0.2f}};
    return 1;
}

static void rsim_bounds(void* state, ak_vec3* lo, ak_vec3* hi) {
    const rsim* r = state;
    *lo = ak_vec3_min(*lo, r->lo);
    *hi = ak_vec3_max(*hi, r->hi);
}

/* A sphere from the camera's eye through pixel (x, y) at THROW_SPEED. */
static bool rsim_shoot(void* state, const ak_raster_camera* cam, int w, int h, float x, float y,
                       char* msg, size_t msg_size) {
    rsim* r = state;
    if (r->failed || !r->run.model || w <= 0 || h <= 0) return false;
    ak_mat4 inv = ak_mat4_inverse(ak_mat4_mul(cam->projection, cam->view));
    float nx = 2.0f * x / (float)w - 1.0f, ny = 1.0f - 2.0f * y / (float)h;
    ak_vec3 p0 = ak_mat4_project_point(inv, ak_vec3_make(nx, ny, -1.0f));
    ak_vec3 p1 = ak_mat4_project_point(inv, ak_vec3_make(nx, ny, 1.0f));
    ak_vec3 dir = ak_vec3_sub(p1, p0);
    if (!ak_vec3_is_finite(p0) || !(ak_vec3_length(dir) > 1e-9f)) return false;
    dir = ak_vec3_normalize(dir);
    const ak_mat4 eye_m = ak_mat4_inverse_affine(cam->view);
    const ak_vec3 eye = ak_mat4_get_translation(eye_m);
    if (!ak_vec3_is_finite(eye)) return false;
    const size_t k = r->next, i = r->user_count + k;
    r->next = (r->next + 1) % THROW_COUNT;
    r->run.positions[i] = ak_vec3_madd(eye, dir, 2.0f * THROW_RADIUS);
    r->run.orientations[i] = ak_quat_identity();
    r->run.velocities[i] = ak_vec3_scale(dir, THROW_SPEED);
    r->run.angular_velocities[i] = ak_vec3_zero();
    if (r->run.job.sleep_timers.ptr) r->run.job.sleep_timers.ptr[i] = 0.0f;
    r->live[k] = true;
    ++r->thrown;
    snprintf(msg, msg_size, "threw a sphere (%zu so far)", r->thrown);
    return true;
}

static void rsim_status(void* state, char* out, size_t n) {
    rsim* r = state;
    snprintf(out, n, "t %.2fs, %zu bodies, %zu thrown, penetration %.2g m%s", r->run.time,
             r->user_count, r->thrown, (double)r->run.max_penetration,
             r->failed ? ", stopped (step failed)" : "");
}

static const view_help_entry rsim_keys[] = {
    {"r", "restart the bodies (also tab)"},
    {"right", "one frame of simulation, paused"},
};

const view_sim view_rigid_sim = {
    .name = "rigid",
    .init = rsim_init,
    .step = rsim_step,
    .reset = rsim_reset,
    .meshes = rsim_meshes,
    .bounds = rsim_bounds,
    .shoot = rsim_shoot,
    .status = rsim_status,
    .destroy = rsim_destroy,
    .failed = rsim_failed,
    .keys = rsim_keys,
    .key_count = sizeof rsim_keys / sizeof rsim_keys[0],
};
