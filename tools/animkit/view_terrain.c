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
    ak_vec3 *skirt_pos, *skirt_nrm; /* the walls from the edges down to the floor */
    uint32_t* skirt_idx;
    size_t skirt_n, skirt_ni;
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
    free(t->skirt_pos);
    free(t->skirt_nrm);
    free(t->skirt_idx);
    free(t);
}

/* Positions, indices, colours and bounds from the heights and normals. The mesh is lifted so
 * that its lowest point is on the floor (y = 0), where the viewer draws its ground: a ridged
 * fractal's lowest height is well above 0 (5.2 m for mountains), which left the terrain
 * floating over the grid. The status line keeps the heights of the heightfield itself. */
static bool tsim_mesh(tsim* t) {
    if (ak_terrain_mesh(&t->desc, (ak_f32_cspan){t->heights, t->n}, (ak_vec3_span){t->positions, t->n}, (ak_vec2_span){0},
                        (ak_u32_span){t->indices, t->ni}) != AK_OK ||
        ak_terrain_colors(&t->desc, (ak_f32_cspan){t->heights, t->n}, (ak_vec3_cspan){t->normals, t->n},
                          (ak_vec4_span){t->colors, t->n}) != AK_OK)
        return false;
    t->lo = ak_vec3_splat(INFINITY), t->hi = ak_vec3_splat(-INFINITY);
    for (size_t i = 0; i < t->n; ++i) t->lo = ak_vec3_min(t->lo, t->positions[i]), t->hi = ak_vec3_max(t->hi, t->positions[i]);
    t->min_h = t->lo.y, t->max_h = t->hi.y;
    for (size_t i = 0; i < t->n; ++i) t->positions[i].y -= t->min_h;
    t->lo.y = 0.0f, t->hi.y = t->max_h - t->min_h;
    /* skirts: each side's edge samples joined to their feet on the floor */
    const uint32_t w = t->desc.width, h = t->desc.height;
    size_t v = 0, k = 0;
    for (int side = 0; side < 4; ++side) {
        const uint32_t count = side < 2 ? w : h;
        const ak_vec3 n = side == 0 ? ak_vec3_make(0, 0, -1) : side == 1 ? ak_vec3_make(0, 0, 1)
                        : side == 2 ? ak_vec3_make(-1, 0, 0) : ak_vec3_make(1, 0, 0);
        for (uint32_t s = 0; s < count; ++s) {
            const uint32_t i = side < 2 ? s : (side == 2 ? 0 : w - 1), j = side < 2 ? (side == 0 ? 0 : h - 1) : s;
            const ak_vec3 top = t->positions[(size_t)j * w + i];
            if (s > 0) {
                const uint32_t a = (uint32_t)v - 2, b = (uint32_t)v;
                const uint32_t q[6] = {a, b, a + 1, b, b + 1, a + 1};
                for (int e = 0; e < 6; ++e) t->skirt_idx[k++] = q[e];
            }
            t->skirt_pos[v] = top, t->skirt_nrm[v++] = n;
            t->skirt_pos[v] = ak_vec3_make(top.x, 0.0f, top.z), t->skirt_nrm[v++] = n;
        }
    }
    t->skirt_n = v, t->skirt_ni = k;
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
            /* `animkit terrain --type ridged`: 20 m like every terrain (30 m over 100 m with
             * 8 octaves drew needles rather than mountains) */
            d.fractal.type = AK_FRACTAL_RIDGED;
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
    const size_t edge = 2u * ((size_t)d.width + d.height);
    t->skirt_pos = malloc(2 * edge * sizeof *t->skirt_pos);
    t->skirt_nrm = malloc(2 * edge * sizeof *t->skirt_nrm);
    t->skirt_idx = malloc(6 * edge * sizeof *t->skirt_idx);
    if (!t->heights || !t->normals || !t->positions || !t->colors || !t->indices || !t->skirt_pos || !t->skirt_nrm ||
        !t->skirt_idx) {
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
    if (cap < 2 || !t->skirt_ni) return 1;
    out[1] = (ak_raster_mesh){.positions = {t->skirt_pos, t->skirt_n}, .normals = {t->skirt_nrm, t->skirt_n},
                              .indices = {t->skirt_idx, t->skirt_ni},
                              .material = {.color = {0.50f, 0.42f, 0.34f, 1}, .specular = 0.02f}};
    return 2;
}

/* Height of the drawn surface under (x, z), bilinear between the samples; false outside. */
static bool tsim_surface(void* state, float x, float z, float* out_height) {
    const tsim* t = state;
    const uint32_t w = t->desc.width, h = t->desc.height;
    if (w < 2 || h < 2 || !(t->hi.x > t->lo.x) || !(t->hi.z > t->lo.z)) return false;
    const float u = (x - t->lo.x) / (t->hi.x - t->lo.x) * (float)(w - 1), v = (z - t->lo.z) / (t->hi.z - t->lo.z) * (float)(h - 1);
    if (!(u >= 0.0f && u <= (float)(w - 1) && v >= 0.0f && v <= (float)(h - 1))) return false;
    uint32_t i = (uint32_t)u, j = (uint32_t)v;
    if (i >= w - 1) i = w - 2;
    if (j >= h - 1) j = h - 2;
    const float fu = u - (float)i, fv = v - (float)j;
    const ak_vec3* p = t->positions;
    const size_t a = (size_t)j * w + i;
    const float y0 = p[a].y + (p[a + 1].y - p[a].y) * fu, y1 = p[a + w].y + (p[a + w + 1].y - p[a + w].y) * fu;
    *out_height = y0 + (y1 - y0) * fv;
    return true;
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
    .surface = tsim_surface,
    .key = tsim_key,
    .status = tsim_status,
    .destroy = tsim_destroy,
    .keys = tsim_keys,
    .key_count = sizeof tsim_keys / sizeof tsim_keys[0],
};
