/* The page's fluid simulation: a viewer plug-in (tools/animkit/view_app.h, view_sim) for the
 * fluid presets, as view_sims.c has for particles, boids and cloth (the desktop viewer has no
 * fluid yet). "fluid:preset:NAME" (dam, pour, splash; "fluid" alone -> dam) with about
 * WEB_FLUID_COUNT particles, stepped with the preset's own dt on the page's one thread, at most
 * MAX_STEPS_PER_FRAME steps a frame (slower than real time when the liquid needs more), drawn as
 * depth-tested points coloured by speed. Keys: r restarts (the viewer's tab/R reset as well). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

#include "view_app.h"
#include "web.h"

#define WEB_FLUID_COUNT 1500
#define MAX_STEPS_PER_FRAME 6

typedef struct fsim {
    ak_fluid_scene scene; /* about 60 KB: the item lists are inline */
    ak_vec3 *pos, *vel;
    ak_vec4* colours;
    uint8_t* scratch;
    size_t cap, n, scratch_size;
    long step_index;
    double carry;
    bool failed;
    ak_vec3 lo, hi;
} fsim;

static void fsim_destroy(void* state) {
    fsim* f = state;
    if (!f) return;
    free(f->pos);
    free(f->vel);
    free(f->colours);
    free(f->scratch);
    free(f);
}

static void fsim_reset(void* state) {
    fsim* f = state;
    f->n = ak_fluid_scene_fill(&f->scene, f->pos, f->vel, f->cap);
    f->step_index = 0;
    f->carry = 0.0;
    f->failed = false;
}

static int fsim_init(void** state, const char* spec, const view_sim_opts* o, char* err, size_t err_size) {
    (void)o;
    *state = NULL;
    const char* name = "dam";
    if (spec && spec[0]) {
        if (strncmp(spec, "preset:", 7) != 0) {
            snprintf(err, err_size, "fluid: the page runs the presets only (fluid:preset:NAME, NAME one of %s)",
                     AK_FLUID_SCENE_PRESETS);
            return CLI_BAD_USAGE;
        }
        name = spec + 7;
    }
    fsim* f = calloc(1, sizeof *f);
    if (!f) {
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    if (ak_fluid_scene_preset(name, WEB_FLUID_COUNT, &f->scene, &diag) != AK_OK) {
        snprintf(err, err_size, "fluid:preset:%s: the presets are %s", name, AK_FLUID_SCENE_PRESETS);
        fsim_destroy(f);
        return CLI_BAD_USAGE;
    }
    f->cap = ak_fluid_scene_capacity(&f->scene);
    f->scratch_size = ak_fluid_scratch_size(f->cap, &f->scene.desc);
    f->pos = malloc(f->cap * sizeof *f->pos);
    f->vel = malloc(f->cap * sizeof *f->vel);
    f->colours = malloc(f->cap * sizeof *f->colours);
    f->scratch = malloc(f->scratch_size ? f->scratch_size : 1);
    if (!f->pos || !f->vel || !f->colours || !f->scratch || f->scratch_size == 0) {
        snprintf(err, err_size, "fluid:preset:%s: out of memory", name);
        fsim_destroy(f);
        return CLI_BAD_INPUT;
    }
    fsim_reset(f);
    /* the camera frames the container box, else the initial liquid and the emitters */
    const ak_fluid_desc* d = &f->scene.desc;
    if (d->box_min.x < d->box_max.x) {
        f->lo = d->box_min;
        f->hi = d->box_max;
    } else {
        f->lo = ak_vec3_splat(INFINITY);
        f->hi = ak_vec3_splat(-INFINITY);
        for (size_t i = 0; i < f->n; ++i) f->lo = ak_vec3_min(f->lo, f->pos[i]), f->hi = ak_vec3_max(f->hi, f->pos[i]);
        for (size_t k = 0; k < f->scene.emitter_count; ++k)
            f->lo = ak_vec3_min(f->lo, f->scene.emitters[k].position), f->hi = ak_vec3_max(f->hi, f->scene.emitters[k].position);
        if (!(f->lo.x <= f->hi.x)) f->lo = ak_vec3_splat(-0.5f), f->hi = ak_vec3_splat(0.5f);
    }
    *state = f;
    return CLI_OK;
}

static void fsim_step(void* state, float dt) {
    fsim* f = state;
    if (f->failed) return;
    const float sdt = f->scene.dt;
    f->carry += (double)dt;
    for (int k = 0; f->carry >= 0.999999 * (double)sdt && k < MAX_STEPS_PER_FRAME; ++k) {
        ak_fluid_step_job job = {
            .desc = &f->scene.desc,
            .dt = sdt,
            .time = (float)((double)f->step_index * sdt),
            .positions = {f->pos, f->cap},
            .velocities = {f->vel, f->cap},
            .particle_count = &f->n,
            .colliders = {f->scene.colliders, f->scene.collider_count},
            .emitters = {f->scene.emitters, f->scene.emitter_count},
            .sinks = {f->scene.sinks, f->scene.sink_count},
            .thread_count = 1,
            .scratch = {f->scratch, f->scratch_size},
        };
        ak_result r = ak_fluid_step_run(&job);
        if (r != AK_OK) {
            fprintf(stderr, "animkit view: fluid: step %ld failed: %s\n", f->step_index, ak_result_string(r));
            f->failed = true;
            return;
        }
        ++f->step_index;
        f->carry -= (double)sdt;
    }
    if (f->carry > (double)sdt) f->carry = 0.0; /* fell behind: slow motion rather than a stall */
}

static ak_result fsim_draw(void* state, ak_raster* raster, const ak_raster_camera* camera, int width, int height) {
    fsim* f = state;
    (void)width;
    for (size_t i = 0; i < f->n; ++i) {
        float s = fminf(ak_vec3_length(f->vel[i]) / 3.0f, 1.0f); /* slow: deep blue, fast: white foam */
        f->colours[i] = (ak_vec4){0.10f + 0.85f * s, 0.35f + 0.6f * s, 0.85f + 0.15f * s, 1.0f};
    }
    ak_raster_points pts = {
        .positions = {f->pos, f->n},
        .colors = {f->colours, f->n},
        .radius = fmaxf(2.0f, (float)height / 220.0f),
    };
    return ak_raster_draw_points(raster, camera, &pts);
}

static void fsim_bounds(void* state, ak_vec3* lo, ak_vec3* hi) {
    fsim* f = state;
    *lo = f->lo;
    *hi = f->hi;
}

static void fsim_status(void* state, char* out, size_t out_size) {
    fsim* f = state;
    snprintf(out, out_size, "fluid: %zu particles, t %.2f s", f->n, (double)f->step_index * (double)f->scene.dt);
}

static bool fsim_failed(void* state) { return ((fsim*)state)->failed; }

static const view_help_entry fsim_keys[] = {{"r", "restart"}};

const view_sim web_fluid_sim = {
    .name = "fluid",
    .init = fsim_init,
    .step = fsim_step,
    .reset = fsim_reset,
    .draw = fsim_draw,
    .bounds = fsim_bounds,
    .status = fsim_status,
    .destroy = fsim_destroy,
    .failed = fsim_failed,
    .keys = fsim_keys,
    .key_count = 1,
};
