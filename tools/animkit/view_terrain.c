/* animkit view: a terrain heightfield (include/animkit/terrain.h) seen with the viewer's camera.
 * `animkit view terrain` shows what `animkit terrain --render` draws with the same defaults;
 * `terrain:preset:hills|mountains|dunes` pick the fractal. Keys regenerate it with the next
 * seed, cycle the fractal type, and erode it a batch of droplets at a time. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "view_app.h"

#define ERODE_DROPLETS 2000u /* per press of E: about 12% of the 129 x 129 cells get a droplet */
#define ERODE_THERMAL 2u

typedef struct tsim {
    ak_terrain_desc desc;
    ak_noise noise;
    ak_fractal_type type0;
    uint64_t seed0, seed;
    uint32_t batches; /* erosion batches run since the last generate */
    size_t n, ni;
    float* heights;
    ak_vec3 *normals, *positions;
    ak_vec4* colors;
    uint32_t* indices;
    ak_vec3 lo, hi;
    float min_h, max_h;
    char name[32];
} tsim;

static const char* type_name(ak_fractal_type t) {
    return t == AK_FRACTAL_RIDGED ? "ridged" : t == AK_FRACTAL_TURBULENCE ? "turbulence" : "fbm";
}

static void tsim_destroy(void* state) {
    tsim* t = state;
    if (!t) return;
    free(t->heights);
    free(t->normals);
    free(t->positions);
    free(t->colors);
    free(t->indices);
    free(t);
}

/* Positions, indices, colours and bounds from the heights and normals. */
static bool tsim_mesh(tsim* t) {
    if (ak_terrain_mesh(&t->desc, (ak_f32_cspan){t->heights, t->n}, (ak_vec3_span){t->positions, t->n}, (ak_vec2_span){0},
                        (ak_u32_span){t->indices, t->ni}) != AK_OK ||
        ak_terrain_colors(&t->desc, (ak_f32_cspan){t->heights, t->n}, (ak_vec3_cspan){t->normals, t->n},
                          (ak_vec4_span){t->colors, t->n}) != AK_OK)
        return false;
    t->lo = ak_vec3_splat(INFINITY), t->hi = ak_vec3_splat(-INFINITY);
    for (size_t i = 0; i < t->n; ++i) t->lo = ak_vec3_min(t->lo, t->positions[i]), t->hi = ak_vec3_max(t->hi, t->positions[i]);
    t->min_h = t->lo.y, t->max_h = t->hi.y;
    return true;
}

static bool tsim_generate(tsim* t) {
    t->noise = ak_noise_make(t->seed);
    t->desc.noise = &t->noise;
    t->batches = 0;
    if (ak_terrain_generate(&t->desc, (ak_f32_span){t->heights, t->n}, (ak_vec3_span){t->normals, t->n}) != AK_OK)
        return false;
    return tsim_mesh(t);
}

static int tsim_init(void** state, const char* spec, const view_sim_opts* o, char* err, size_t err_size) {
    /* the defaults of `animkit terrain` but for the grid: 129 x 129 samples rather than 257 x 257
     * (a quarter of the triangles, about half the CPU time of a 960 x 600 frame; docs/view.md) */
    ak_terrain_desc d = {.width = 129, .height = 129, .world_size = 100, .height_scale = 20,
                         .fractal = {.type = AK_FRACTAL_FBM, .octaves = 8}};
    const char* name = "hills";
    if (strncmp(spec, "preset:", 7) == 0) {
        name = spec + 7;
        if (strcmp(name, "hills") == 0) {
        } else if (strcmp(name, "mountains") == 0) {
            d.fractal.type = AK_FRACTAL_RIDGED, d.height_scale = 30;
        } else if (strcmp(name, "dunes") == 0) {
            d.fractal.type = AK_FRACTAL_TURBULENCE, d.fractal.octaves = 4, d.height_scale = 8;
        } else {
            snprintf(err, err_size, "terrain:preset:%s: the presets are hills, mountains, dunes", name);
            return CLI_BAD_USAGE;
        }
    } else if (spec[0]) {
        snprintf(err, err_size, "terrain:%s: terrain takes no scene file; use terrain or terrain:preset:hills|mountains|dunes",
                 spec);
        return CLI_BAD_USAGE;
    }
    tsim* t = calloc(1, sizeof *t);
    if (!t) {
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    snprintf(t->name, sizeof t->name, "%s", name);
    d.thread_count = o->threads > 0 ? (uint32_t)o->threads : 1;
    t->desc = d;
    t->type0 = d.fractal.type;
    t->seed0 = t->seed = o->has_seed ? o->seed : 0; /* `animkit terrain` seeds with 0 */
    t->noise = ak_noise_make(t->seed);
    t->desc.noise = &t->noise;
    t->n = (size_t)d.width * d.height;
    t->ni = ak_terrain_index_count(&t->desc); /* 0 without a noise */
    t->heights = malloc(t->n * sizeof *t->heights);
    t->normals = malloc(t->n * sizeof *t->normals);
    t->positions = malloc(t->n * sizeof *t->positions);
    t->colors = malloc(t->n * sizeof *t->colors);
    t->indices = malloc(t->ni * sizeof *t->indices);
    if (!t->heights || !t->normals || !t->positions || !t->colors || !t->indices) {
        snprintf(err, err_size, "out of memory for a %ux%u terrain", d.width, d.height);
        tsim_destroy(t);
        return CLI_BAD_INPUT;
    }
    if (!tsim_generate(t)) {
        snprintf(err, err_size, "cannot generate the terrain");
        tsim_destroy(t);
        return CLI_BAD_INPUT;
    }
    *state = t;
    return CLI_OK;
}

static void tsim_reset(void* state) {
    tsim* t = state;
    t->seed = t->seed0;
    t->desc.fractal.type = t->type0;
    tsim_generate(t);
}

static size_t tsim_meshes(void* state, ak_raster_mesh* out, size_t cap) {
    tsim* t = state;
    if (cap < 1) return 0;
    out[0] = (ak_raster_mesh){.positions = {t->positions, t->n}, .normals = {t->normals, t->n}, .colors = {t->colors, t->n},
                              .indices = {t->indices, t->ni}, .material = {.color = {1, 1, 1, 1}, .specular = 0.05f}};
    return 1;
}

static void tsim_bounds(void* state, ak_vec3* lo, ak_vec3* hi) {
    tsim* t = state;
    *lo = ak_vec3_min(*lo, t->lo);
    *hi = ak_vec3_max(*hi, t->hi);
}

static bool tsim_key(void* state, int key, char* msg, size_t msg_size) {
    tsim* t = state;
    switch (key) {
    case 'g':
        ++t->seed;
        if (!tsim_generate(t)) snprintf(msg, msg_size, "cannot generate the terrain");
        else snprintf(msg, msg_size, "seed %llu", (unsigned long long)t->seed);
        return true;
    case 't':
        t->desc.fractal.type = t->desc.fractal.type == AK_FRACTAL_FBM      ? AK_FRACTAL_RIDGED
                               : t->desc.fractal.type == AK_FRACTAL_RIDGED ? AK_FRACTAL_TURBULENCE
                                                                          : AK_FRACTAL_FBM;
        if (!tsim_generate(t)) snprintf(msg, msg_size, "cannot generate the terrain");
        else snprintf(msg, msg_size, "fractal %s", type_name(t->desc.fractal.type));
        return true;
    case 'e': {
        /* each batch has its own droplet seed, so pressing E twice erodes different places */
        const ak_terrain_erosion e = {.droplets = ERODE_DROPLETS, .thermal_iterations = ERODE_THERMAL,
                                      .seed = t->seed * 1000003u + t->batches};
        ak_result r = ak_terrain_erode(&e, &t->desc, (ak_f32_span){t->heights, t->n}, NULL, NULL);
        if (r == AK_OK) r = ak_terrain_normals(&t->desc, (ak_f32_cspan){t->heights, t->n}, (ak_vec3_span){t->normals, t->n});
        if (r != AK_OK) {
            snprintf(msg, msg_size, "cannot erode: %s", ak_result_string(r));
            return true;
        }
        ++t->batches;
        if (!tsim_mesh(t)) snprintf(msg, msg_size, "cannot mesh the terrain");
        else snprintf(msg, msg_size, "eroded %u droplets", ERODE_DROPLETS);
        return true;
    }
    default: return false;
    }
}

static void tsim_status(void* state, char* out, size_t n) {
    tsim* t = state;
    snprintf(out, n, "%s %ux%u %s seed %llu, heights %.2f..%.2f m, %lu droplets", t->name, t->desc.width, t->desc.height,
             type_name(t->desc.fractal.type), (unsigned long long)t->seed, (double)t->min_h, (double)t->max_h,
             (unsigned long)t->batches * ERODE_DROPLETS);
}

static const view_help_entry tsim_keys[] = {
    {"g", "new terrain (next seed)"},
    {"t", "next fractal (fbm, ridged, turbulence)"},
    {"e", "erode (2000 droplets, 2 thermal passes)"},
    {"r", "back to the first terrain (also tab)"},
};

const view_sim view_terrain_sim = {
    .name = "terrain",
    .init = tsim_init,
    .reset = tsim_reset,
    .meshes = tsim_meshes,
    .bounds = tsim_bounds,
    .key = tsim_key,
    .status = tsim_status,
    .destroy = tsim_destroy,
    .keys = tsim_keys,
    .key_count = sizeof tsim_keys / sizeof tsim_keys[0],
};
