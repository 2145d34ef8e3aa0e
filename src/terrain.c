/* Terrain: heightfields from fractal noise (normals from the analytic gradient), hydraulic and
 * thermal erosion, colours, meshes, OBJ and 16-bit PNG files. */
#include <math.h>
#include <png.h> /* libpng classic API: 16-bit greyscale written row by row, no buffer */
#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#include <animkit/terrain.h>

#include "internal.h" /* ak_atomic_file: outputs written whole or not at all */
#include "tasks.h"

#define AKP_TERRAIN_MAX_SIDE 16384u

/* ---- desc -------------------------------------------------------------------------------- */

ak_terrain_desc ak_terrain_desc_resolved(const ak_terrain_desc* desc) {
    ak_terrain_desc d;
    if (desc) d = *desc;
    else memset(&d, 0, sizeof d);
    if (d.width == 0) d.width = 257;
    if (d.height == 0) d.height = 257;
    if (d.world_size == 0.0f) d.world_size = 100.0f;
    if (d.height_scale == 0.0f) d.height_scale = d.world_size / 5.0f;
    if (d.feature_size == 0.0f) d.feature_size = d.world_size / 4.0f;
    return d;
}

static bool pos_finite(float v) { return isfinite(v) && v > 0.0f; }

ak_result ak_terrain_desc_validate(const ak_terrain_desc* desc) {
    if (!desc || !desc->noise) return AK_ERR_NULL_ARG;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    if (d.width < 2 || d.height < 2 || d.width > AKP_TERRAIN_MAX_SIDE || d.height > AKP_TERRAIN_MAX_SIDE)
        return AK_ERR_BAD_ARG;
    if (!pos_finite(d.world_size) || !pos_finite(d.height_scale) || !pos_finite(d.feature_size) || d.thread_count > 64)
        return AK_ERR_BAD_ARG;
    if (d.world_size > 1e7f || d.height_scale > 1e7f || d.feature_size < d.world_size * 1e-6f) return AK_ERR_BAD_ARG;
    return ak_fractal_desc_validate(&d.fractal);
}

static float cell_size(const ak_terrain_desc* d) { return d->world_size / (float)(d->width - 1); }

ak_vec3 ak_terrain_sample_position(const ak_terrain_desc* desc, uint32_t i, uint32_t j, float y) {
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const float c = cell_size(&d);
    const float x0 = -0.5f * d.world_size, z0 = -0.5f * c * (float)(d.height - 1);
    return ak_vec3_make(x0 + (float)i * c, y, z0 + (float)j * c);
}

static size_t sample_count(const ak_terrain_desc* d) { return (size_t)d->width * d->height; }

/* height = height_scale * F / hi */
static float height_factor(const ak_terrain_desc* d) {
    float lo, hi;
    ak_fractal_range(&d->fractal, 2, &lo, &hi);
    return d->height_scale / hi;
}

/* ---- generate ---------------------------------------------------------------------------- */

/* Points go to the noise batch job in chunks with their coordinates computed as the grid job
 * does (origin + index * spacing, per axis), so results do not depend on the split. */
#define GEN_CHUNK 1024u

typedef struct gen_task {
    const ak_terrain_desc* d;
    float ox, oz, step, k, kg;
    float* heights;
    ak_vec3* normals;
    size_t begin, end;
} gen_task;

static void* gen_thread(void* arg) {
    const gen_task* t = (const gen_task*)arg;
    const uint32_t w = t->d->width;
    float xs[GEN_CHUNK], zs[GEN_CHUNK], gx[GEN_CHUNK], gz[GEN_CHUNK];
    for (size_t b = t->begin; b < t->end; b += GEN_CHUNK) {
        const size_t m = t->end - b < GEN_CHUNK ? t->end - b : GEN_CHUNK;
        for (size_t q = 0; q < m; ++q) {
            const size_t a = b + q;
            xs[q] = t->ox + (float)(a % w) * t->step;
            zs[q] = t->oz + (float)(a / w) * t->step;
        }
        ak_noise_job job = {.noise = t->d->noise, .fractal = t->d->fractal, .dimensions = 2, .x = {xs, m},
                            .y = {zs, m}, .out_values = {t->heights + b, m}, .skip_simd = t->d->skip_simd};
        if (t->normals) {
            job.out_gradient_x = (ak_f32_span){gx, m};
            job.out_gradient_y = (ak_f32_span){gz, m};
        }
        ak_noise_job_run(&job); /* valid: checked by the caller */
        for (size_t q = 0; q < m; ++q) {
            t->heights[b + q] *= t->k;
            if (t->normals)
                t->normals[b + q] = ak_vec3_normalize(ak_vec3_make(-gx[q] * t->kg, 1.0f, -gz[q] * t->kg));
        }
    }
    return NULL;
}

ak_result ak_terrain_generate(const ak_terrain_desc* desc, ak_f32_span out_heights, ak_vec3_span out_normals) {
    ak_result r = ak_terrain_desc_validate(desc);
    if (r != AK_OK) return r;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const size_t n = sample_count(&d);
    if (!out_heights.ptr) return AK_ERR_NULL_ARG;
    if (out_heights.count < n || (out_normals.ptr && out_normals.count < n)) return AK_ERR_SPAN_SMALL;
    const ak_vec3 origin = ak_terrain_sample_position(&d, 0, 0, 0.0f);
    const float c = cell_size(&d), inv_f = 1.0f / d.feature_size, k = height_factor(&d);
    uint32_t threads = d.thread_count > 1 ? d.thread_count : 1;
    if (threads > n / GEN_CHUNK + 1) threads = (uint32_t)(n / GEN_CHUNK + 1);
    gen_task tasks[64];
    const size_t per = (n + threads - 1) / threads;
    for (uint32_t t = 0; t < threads; ++t) {
        const size_t b = (size_t)t * per, e = b + per;
        tasks[t] = (gen_task){&d, origin.x * inv_f, origin.z * inv_f, c * inv_f, k, k * inv_f, out_heights.ptr,
                              out_normals.ptr, b < n ? b : n, e < n ? e : n};
    }
    akp_run_tasks(gen_thread, tasks, sizeof(gen_task), threads);
    return AK_OK;
}

/* ---- normals from heights -------------------------------------------------------------- */

ak_result ak_terrain_normals(const ak_terrain_desc* desc, ak_f32_cspan heights, ak_vec3_span out_normals) {
    ak_result r = ak_terrain_desc_validate(desc);
    if (r != AK_OK) return r;
    if (!heights.ptr || !out_normals.ptr) return AK_ERR_NULL_ARG;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const size_t n = sample_count(&d);
    if (heights.count < n || out_normals.count < n) return AK_ERR_SPAN_SMALL;
    const float c = cell_size(&d);
    const uint32_t w = d.width, h = d.height;
    for (uint32_t j = 0; j < h; ++j) {
        for (uint32_t i = 0; i < w; ++i) {
            const uint32_t i0 = i ? i - 1 : 0, i1 = i + 1 < w ? i + 1 : i;
            const uint32_t j0 = j ? j - 1 : 0, j1 = j + 1 < h ? j + 1 : j;
            const float dx = (heights.ptr[(size_t)j * w + i1] - heights.ptr[(size_t)j * w + i0]) / ((float)(i1 - i0) * c);
            const float dz = (heights.ptr[(size_t)j1 * w + i] - heights.ptr[(size_t)j0 * w + i]) / ((float)(j1 - j0) * c);
            out_normals.ptr[(size_t)j * w + i] = ak_vec3_normalize(ak_vec3_make(-dx, 1.0f, -dz));
        }
    }
    return AK_OK;
}

/* ---- erosion ------------------------------------------------------------------------------ */

static ak_terrain_erosion erosion_resolved(const ak_terrain_erosion* e) {
    ak_terrain_erosion r;
    if (e) r = *e;
    else memset(&r, 0, sizeof r);
    if (r.inertia == 0.0f) r.inertia = 0.05f;
    if (r.capacity == 0.0f) r.capacity = 4.0f;
    if (r.deposition == 0.0f) r.deposition = 0.3f;
    if (r.erosion == 0.0f) r.erosion = 0.3f;
    if (r.evaporation == 0.0f) r.evaporation = 0.01f;
    if (r.min_slope == 0.0f) r.min_slope = 0.01f;
    if (r.max_steps == 0) r.max_steps = 64;
    if (r.radius == 0) r.radius = 3;
    if (r.talus == 0.0f) r.talus = 0.8f;
    return r;
}

static bool unit_range(float v) { return v >= 0.0f && v <= 1.0f; }

/* Height and gradient (per cell, in cell units) at a point inside the grid, bilinear. */
static float bilinear(const float* hm, uint32_t w, float px, float pz, float* gx, float* gz) {
    const uint32_t i = (uint32_t)px, j = (uint32_t)pz;
    const float u = px - (float)i, v = pz - (float)j;
    const size_t a = (size_t)j * w + i;
    const float h00 = hm[a], h10 = hm[a + 1], h01 = hm[a + w], h11 = hm[a + w + 1];
    *gx = (h10 - h00) * (1.0f - v) + (h11 - h01) * v;
    *gz = (h01 - h00) * (1.0f - u) + (h11 - h10) * u;
    return h00 * (1 - u) * (1 - v) + h10 * u * (1 - v) + h01 * (1 - u) * v + h11 * u * v;
}

ak_result ak_terrain_erode(const ak_terrain_erosion* erosion, const ak_terrain_desc* desc, ak_f32_span heights,
                           void (*progress)(size_t done, size_t total, void* user), void* user) {
    ak_result r = ak_terrain_desc_validate(desc);
    if (r != AK_OK) return r;
    if (!erosion || !heights.ptr) return AK_ERR_NULL_ARG;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const ak_terrain_erosion e = erosion_resolved(erosion);
    const size_t n = sample_count(&d);
    if (heights.count < n) return AK_ERR_SPAN_SMALL;
    if (!unit_range(e.inertia) || !unit_range(e.deposition) || !unit_range(e.erosion) || !unit_range(e.evaporation) ||
        !pos_finite(e.capacity) || e.capacity > 1e3f || !pos_finite(e.min_slope) || !pos_finite(e.talus) ||
        e.max_steps > 4096 || e.radius > 8 || e.droplets > 100000000u || e.thermal_iterations > 100000u)
        return AK_ERR_BAD_ARG;
    float base = heights.ptr[0]; /* the base level: no cell is eroded below the lowest start height */
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(heights.ptr[i])) return AK_ERR_BAD_DATA;
        base = fminf(base, heights.ptr[i]);
    }
    float* hm = heights.ptr;
    const uint32_t w = d.width, hgt = d.height;
    const float c = cell_size(&d), inv_c = 1.0f / c;
    const size_t total = (size_t)e.droplets + e.thermal_iterations;

    /* erosion brush: cells within the radius, weights max(0, radius - distance), normalised */
    int bdx[289], bdz[289];
    float bw[289], bsum = 0.0f;
    int bcount = 0;
    const int rad = (int)e.radius;
    for (int dz = -rad; dz <= rad; ++dz)
        for (int dx = -rad; dx <= rad; ++dx) {
            const float dist = sqrtf((float)(dx * dx + dz * dz));
            if (dist < (float)rad) {
                bdx[bcount] = dx, bdz[bcount] = dz, bw[bcount] = (float)rad - dist;
                bsum += bw[bcount++];
            }
        }
    for (int b = 0; b < bcount; ++b) bw[b] /= bsum;

    ak_rng rng = ak_rng_make(e.seed);
    const float gravity = 4.0f;
    for (uint32_t drop = 0; drop < e.droplets; ++drop) {
        if (progress && (drop & 4095u) == 0) progress(drop, total, user);
        float px = ak_rng_float(&rng) * (float)(w - 1), pz = ak_rng_float(&rng) * (float)(hgt - 1);
        float dirx = 0.0f, dirz = 0.0f, speed = 1.0f, water = 1.0f, sediment = 0.0f;
        for (uint32_t step = 0; step < e.max_steps; ++step) {
            if (!(px >= 0.0f && pz >= 0.0f && px < (float)(w - 1) && pz < (float)(hgt - 1))) break;
            const uint32_t ci = (uint32_t)px, cj = (uint32_t)pz;
            const float u = px - (float)ci, v = pz - (float)cj;
            float gx, gz;
            const float h0 = bilinear(hm, w, px, pz, &gx, &gz) * inv_c; /* cell units */
            gx *= inv_c;
            gz *= inv_c;
            dirx = dirx * e.inertia - gx * (1.0f - e.inertia);
            dirz = dirz * e.inertia - gz * (1.0f - e.inertia);
            float len = sqrtf(dirx * dirx + dirz * dirz);
            if (len < 1e-12f) {
                const float a = ak_rng_float(&rng) * AK_TWO_PI;
                dirx = cosf(a), dirz = sinf(a), len = 1.0f;
            }
            dirx /= len;
            dirz /= len;
            const float nx = px + dirx, nz = pz + dirz;
            /* a droplet leaving the grid stops without eroding (Beyer 2015): eroding towards an
             * edge assumed lower dug the border cells without bound (-868 m after 10^6 droplets
             * on a +-9 m terrain) */
            if (!(nx >= 0.0f && nz >= 0.0f && nx < (float)(w - 1) && nz < (float)(hgt - 1))) break;
            float tx, tz;
            const float h1 = bilinear(hm, w, nx, nz, &tx, &tz) * inv_c;
            const float dh = h1 - h0;
            const float cap = fmaxf(-dh, e.min_slope) * speed * water * e.capacity;
            const size_t a = (size_t)cj * w + ci;
            if (sediment > cap || dh > 0.0f) {
                const float drop_amount = dh > 0.0f ? fminf(dh, sediment) : (sediment - cap) * e.deposition;
                sediment -= drop_amount;
                const float m = drop_amount * c; /* back to metres */
                hm[a] += m * (1 - u) * (1 - v);
                hm[a + 1] += m * u * (1 - v);
                hm[a + w] += m * (1 - u) * v;
                hm[a + w + 1] += m * u * v;
            } else {
                const float take = fminf((cap - sediment) * e.erosion, -dh);
                /* the brush's weights renormalised over the cells inside the grid, and the
                 * sediment picked up is exactly the material removed (the clipped brush used
                 * to create sediment near a border: a 3x3 grid rose to 1e23 m); no cell goes
                 * below the base level (as Beyer's heights stay >= 0: without it, droplets
                 * draining off the edge deepened their valleys without bound, -5e9 m) */
                float inside_w = 0.0f;
                for (int b = 0; b < bcount; ++b) {
                    const int bi = (int)ci + bdx[b], bj = (int)cj + bdz[b];
                    if (bi >= 0 && bj >= 0 && bi < (int)w && bj < (int)hgt) inside_w += bw[b];
                }
                float removed = 0.0f;
                for (int b = 0; b < bcount; ++b) {
                    const int bi = (int)ci + bdx[b], bj = (int)cj + bdz[b];
                    if (bi < 0 || bj < 0 || bi >= (int)w || bj >= (int)hgt) continue;
                    float* cell = &hm[(size_t)bj * w + (size_t)bi];
                    const float m = fminf(take * (bw[b] / inside_w) * c, fmaxf(*cell - base, 0.0f));
                    *cell -= m;
                    removed += m;
                }
                sediment += removed * inv_c;
            }
            speed = sqrtf(fmaxf(speed * speed - dh * gravity, 0.0f));
            water *= 1.0f - e.evaporation;
            px = nx, pz = nz;
        }
    }

    /* thermal: material above the talus difference slides to the lowest lower neighbour */
    const float talus = e.talus * c;
    for (uint32_t it = 0; it < e.thermal_iterations; ++it) {
        if (progress) progress((size_t)e.droplets + it, total, user);
        for (uint32_t j = 0; j < hgt; ++j)
            for (uint32_t i = 0; i < w; ++i) {
                const size_t a = (size_t)j * w + i;
                size_t best = a;
                float best_d = talus;
                const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
                for (int k = 0; k < 4; ++k) {
                    const int ni = (int)i + di[k], nj = (int)j + dj[k];
                    if (ni < 0 || nj < 0 || ni >= (int)w || nj >= (int)hgt) continue;
                    const size_t b = (size_t)nj * w + (size_t)ni;
                    if (hm[a] - hm[b] > best_d) best_d = hm[a] - hm[b], best = b;
                }
                if (best != a) {
                    const float move = 0.25f * (best_d - talus);
                    hm[a] -= move;
                    hm[best] += move;
                }
            }
    }
    if (progress) progress(total, total, user);
    return AK_OK;
}

/* ---- colours and mesh ------------------------------------------------------------------- */

static float smooth(float e0, float e1, float x) {
    float t = (x - e0) / (e1 - e0);
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    return t * t * (3.0f - 2.0f * t);
}

static ak_vec4 mix4(ak_vec4 a, ak_vec4 b, float t) {
    return ak_vec4_make(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t, 1.0f);
}

ak_result ak_terrain_colors(const ak_terrain_desc* desc, ak_f32_cspan heights, ak_vec3_cspan normals,
                           ak_vec4_span out_colors) {
    ak_result r = ak_terrain_desc_validate(desc);
    if (r != AK_OK) return r;
    if (!heights.ptr || !normals.ptr || !out_colors.ptr) return AK_ERR_NULL_ARG;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const size_t n = sample_count(&d);
    if (heights.count < n || normals.count < n || out_colors.count < n) return AK_ERR_SPAN_SMALL;
    float lo, hi;
    ak_fractal_range(&d.fractal, 2, &lo, &hi);
    const float hlo = d.height_scale * lo / hi, hhi = d.height_scale;
    const ak_vec4 sand = ak_vec4_make(0.78f, 0.72f, 0.52f, 1), grass = ak_vec4_make(0.36f, 0.52f, 0.24f, 1);
    const ak_vec4 forest = ak_vec4_make(0.22f, 0.38f, 0.18f, 1), rock = ak_vec4_make(0.48f, 0.45f, 0.42f, 1);
    const ak_vec4 snow = ak_vec4_make(0.95f, 0.96f, 0.98f, 1);
    for (size_t i = 0; i < n; ++i) {
        const float t = (heights.ptr[i] - hlo) / (hhi - hlo); /* 0 low .. 1 high */
        const float up = normals.ptr[i].y;                    /* 1 flat .. 0 vertical */
        ak_vec4 col = mix4(sand, grass, smooth(0.02f, 0.12f, t));
        col = mix4(col, forest, smooth(0.25f, 0.45f, t) * (1.0f - smooth(0.6f, 0.75f, t)));
        col = mix4(col, snow, smooth(0.62f, 0.75f, t) * smooth(0.7f, 0.85f, up));
        col = mix4(col, rock, 1.0f - smooth(0.72f, 0.86f, up));
        out_colors.ptr[i] = col;
    }
    return AK_OK;
}

size_t ak_terrain_index_count(const ak_terrain_desc* desc) {
    if (ak_terrain_desc_validate(desc) != AK_OK) return 0;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    return (size_t)(d.width - 1) * (d.height - 1) * 6u;
}

ak_result ak_terrain_mesh(const ak_terrain_desc* desc, ak_f32_cspan heights, ak_vec3_span out_positions,
                          ak_vec2_span out_uvs, ak_u32_span out_indices) {
    ak_result r = ak_terrain_desc_validate(desc);
    if (r != AK_OK) return r;
    if (!heights.ptr || !out_positions.ptr) return AK_ERR_NULL_ARG;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const size_t n = sample_count(&d), ni = ak_terrain_index_count(&d);
    if (heights.count < n || out_positions.count < n || (out_uvs.ptr && out_uvs.count < n) ||
        (out_indices.ptr && out_indices.count < ni))
        return AK_ERR_SPAN_SMALL;
    if (n > 0xFFFFFFFFu) return AK_ERR_BAD_ARG;
    const uint32_t w = d.width, h = d.height;
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            const size_t a = (size_t)j * w + i;
            out_positions.ptr[a] = ak_terrain_sample_position(&d, i, j, heights.ptr[a]);
            if (out_uvs.ptr) out_uvs.ptr[a] = ak_vec2_make((float)i / (float)(w - 1), (float)j / (float)(h - 1));
        }
    if (out_indices.ptr) {
        size_t k = 0;
        for (uint32_t j = 0; j + 1 < h; ++j)
            for (uint32_t i = 0; i + 1 < w; ++i) {
                const uint32_t a = j * w + i, b = a + 1, c = a + w, e = c + 1;
                out_indices.ptr[k++] = a, out_indices.ptr[k++] = c, out_indices.ptr[k++] = b;
                out_indices.ptr[k++] = b, out_indices.ptr[k++] = c, out_indices.ptr[k++] = e;
            }
    }
    return AK_OK;
}

/* ---- files -------------------------------------------------------------------------------- */

ak_result ak_terrain_write_obj(const char* path, const ak_terrain_desc* desc, ak_f32_cspan heights,
                               ak_vec3_cspan normals) {
    ak_result r = ak_terrain_desc_validate(desc);
    if (r != AK_OK) return r;
    if (!path || !heights.ptr || !normals.ptr) return AK_ERR_NULL_ARG;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const size_t n = sample_count(&d);
    if (heights.count < n || normals.count < n) return AK_ERR_SPAN_SMALL;
    ak_atomic_file out; /* a temporary renamed over path once complete (internal.h) */
    if (ak_atomic_file_open(&out, path) != AK_OK) return AK_ERR_IO;
    FILE* f = out.f;
    const uint32_t w = d.width, h = d.height;
    fprintf(f, "# animkit terrain %ux%u, world %g m\no terrain\n", w, h, (double)d.world_size);
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            const ak_vec3 p = ak_terrain_sample_position(&d, i, j, heights.ptr[(size_t)j * w + i]);
            fprintf(f, "v %.7g %.7g %.7g\n", (double)p.x, (double)p.y, (double)p.z);
        }
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i)
            fprintf(f, "vt %.7g %.7g\n", (double)i / (w - 1), 1.0 - (double)j / (h - 1));
    for (size_t a = 0; a < n; ++a)
        fprintf(f, "vn %.6g %.6g %.6g\n", (double)normals.ptr[a].x, (double)normals.ptr[a].y, (double)normals.ptr[a].z);
    for (uint32_t j = 0; j + 1 < h; ++j)
        for (uint32_t i = 0; i + 1 < w; ++i) {
            const size_t a = (size_t)j * w + i + 1, b = a + 1, c = a + w, e = c + 1; /* 1-based */
            fprintf(f, "f %zu/%zu/%zu %zu/%zu/%zu %zu/%zu/%zu\n", a, a, a, c, c, c, b, b, b);
            fprintf(f, "f %zu/%zu/%zu %zu/%zu/%zu %zu/%zu/%zu\n", b, b, b, c, c, c, e, e, e);
        }
    return ak_atomic_file_commit(&out);
}

typedef struct png_jmp {
    jmp_buf jmp;
} png_jmp;

static void png_error_fn(png_structp png, png_const_charp msg) {
    (void)msg;
    png_jmp* j = (png_jmp*)png_get_error_ptr(png);
    longjmp(j->jmp, 1);
}
static void png_warning_fn(png_structp png, png_const_charp msg) { (void)png, (void)msg; }

/* The libpng part; every local that lives across setjmp is set before it and never changed. */
static bool write_png16_rows(FILE* f, const float* hm, uint32_t w, uint32_t h, double lo, double scale) {
    png_jmp jb;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &jb, png_error_fn, png_warning_fn);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        return false;
    }
    if (setjmp(jb.jmp)) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, w, h, 16, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    uint8_t row[2 * AKP_TERRAIN_MAX_SIDE];
    for (uint32_t j = 0; j < h; ++j) {
        for (uint32_t i = 0; i < w; ++i) {
            double t = ((double)hm[(size_t)j * w + i] - lo) * scale;
            t = t < 0.0 ? 0.0 : t > 65535.0 ? 65535.0 : t;
            const uint16_t v = (uint16_t)lround(t);
            row[2 * i] = (uint8_t)(v >> 8); /* PNG samples are big-endian */
            row[2 * i + 1] = (uint8_t)(v & 255u);
        }
        png_write_row(png, row);
    }
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return true;
}

ak_result ak_terrain_write_png16(const char* path, const ak_terrain_desc* desc, ak_f32_cspan heights, float lo,
                                 float hi) {
    ak_result r = ak_terrain_desc_validate(desc);
    if (r != AK_OK) return r;
    if (!path || !heights.ptr) return AK_ERR_NULL_ARG;
    const ak_terrain_desc d = ak_terrain_desc_resolved(desc);
    const size_t n = sample_count(&d);
    if (heights.count < n) return AK_ERR_SPAN_SMALL;
    if (!isfinite(lo) || !isfinite(hi) || lo > hi) return AK_ERR_BAD_ARG;
    if (lo == 0.0f && hi == 0.0f) {
        lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < n; ++i) {
            if (!isfinite(heights.ptr[i])) return AK_ERR_BAD_DATA;
            lo = fminf(lo, heights.ptr[i]);
            hi = fmaxf(hi, heights.ptr[i]);
        }
    }
    const double scale = hi > lo ? 65535.0 / ((double)hi - lo) : 0.0;
    ak_atomic_file out; /* a temporary renamed over path once complete (internal.h) */
    if (ak_atomic_file_open(&out, path) != AK_OK) return AK_ERR_IO;
    if (!write_png16_rows(out.f, heights.ptr, d.width, d.height, lo, scale)) {
        ak_atomic_file_abort(&out);
        return AK_ERR_IO;
    }
    return ak_atomic_file_commit(&out);
}
