/* animkit terrain: heightfields from fractal noise, erosion, meshes and files.
 *
 * What it does:
 *   - a W x H heightfield over a square-celled world rectangle from any fractal of noise.h,
 *     with normals from the fractal's analytic gradient (no finite differences);
 *   - a particle-based hydraulic erosion pass (water droplets that pick up and drop sediment,
 *     after H. T. Beyer 2015, "Implementation of a method for hydraulic erosion", simplified)
 *     and a thermal pass (material above the talus slope slides to the lowest neighbour);
 *   - normals from the heights (after erosion), colours by height and slope, and a triangle
 *     mesh (positions, normals, UVs, colours, indices) for the raster module or a file;
 *   - files: Wavefront OBJ with normals and UVs, and a 16-bit greyscale PNG heightmap.
 *
 * What it does NOT do: level of detail, tiling across several heightfields, texture splatting,
 * rivers or lakes as water surfaces. Rendering is the raster module's (the animkit CLI's
 * `terrain` command renders PNG stills and GIF turntable flights).
 *
 * Usage:
 *     ak_noise n = ak_noise_make(7);
 *     ak_terrain_desc d = { .noise = &n, .width = 257, .height = 257, .world_size = 100,
 *                           .height_scale = 20, .fractal = { .type = AK_FRACTAL_RIDGED, .octaves = 8 } };
 *     float* h = malloc(257 * 257 * sizeof *h);  ak_vec3* nrm = malloc(257 * 257 * sizeof *nrm);
 *     ak_terrain_generate(&d, (ak_f32_span){h, 257 * 257}, (ak_vec3_span){nrm, 257 * 257});
 *     ak_terrain_erode(&(ak_terrain_erosion){ .droplets = 50000 }, &d, (ak_f32_span){h, 257 * 257},
 *                      NULL, NULL);     // no progress callback
 *     ak_terrain_normals(&d, (ak_f32_cspan){h, 257 * 257}, (ak_vec3_span){nrm, 257 * 257});
 *     ak_terrain_write_png16("height.png", &d, (ak_f32_cspan){h, 257 * 257}, 0, 0);
 *
 * Layout: sample (i, j), i < width along +x and j < height along +z, is at world
 * x = (i / (width - 1) - 0.5) * world_size, z = (j / (width - 1) - 0.5 * (height - 1) /
 * (width - 1)) * world_size, y = its height: cells are square, centred on the origin. Arrays are
 * row-major, index j * width + i.
 *
 * Ownership and threading: every array is caller-owned; nothing allocates or keeps a pointer.
 * Functions are reentrant; generate may start desc.thread_count pthreads (joined before return).
 */
#ifndef ANIMKIT_TERRAIN_H
#define ANIMKIT_TERRAIN_H

#include "noise.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The heightfield: what it samples and where. */
typedef struct ak_terrain_desc {
    const ak_noise* noise;    /* required */
    ak_fractal_desc fractal;  /* the height function (frequency multiplies 1 / feature_size) */
    uint32_t width, height;   /* samples along x and z, 2..16384 each; 0 -> 257 */
    float world_size;         /* metres from the first to the last sample along x; 0 -> 100 */
    float height_scale;       /* metres: heights are height_scale * F / hi, with [lo, hi] the
                                 fractal's documented range, so they lie in
                                 height_scale * [lo / hi, 1]; 0 -> world_size / 5 */
    float feature_size;       /* metres per noise lattice cell of the first octave;
                                 0 -> world_size / 4 */
    uint32_t thread_count;    /* 0 or 1 -> calling thread; at most 64 */
    bool skip_simd;           /* false -> SIMD noise kernels (AVX-512 or AVX2) where available */
} ak_terrain_desc;

/* The desc with zero fields replaced by their defaults. */
AK_API ak_terrain_desc ak_terrain_desc_resolved(const ak_terrain_desc* desc);
/* AK_OK, AK_ERR_NULL_ARG (noise), AK_ERR_BAD_ARG (a size outside 2..16384, non-positive or
 * non-finite world_size, height_scale, feature_size, thread_count > 64, a bad fractal). */
AK_API ak_result ak_terrain_desc_validate(const ak_terrain_desc* desc);

/* World position of sample (i, j) with height y. */
AK_API ak_vec3 ak_terrain_sample_position(const ak_terrain_desc* desc, uint32_t i, uint32_t j, float y);

/* Sample the heights (out_heights.count >= width * height) and, when out_normals.ptr is not
 * NULL, the unit normals (-dh/dx, 1, -dh/dz) / |.| from the fractal's analytic gradient.
 * Returns the validate codes or AK_ERR_SPAN_SMALL; nothing is written on error. */
AK_API ak_result ak_terrain_generate(const ak_terrain_desc* desc, ak_f32_span out_heights, ak_vec3_span out_normals);

/* Unit normals from the heights by central differences (one-sided at the border): use after
 * erosion. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (desc), AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_terrain_normals(const ak_terrain_desc* desc, ak_f32_cspan heights, ak_vec3_span out_normals);

/* Erosion parameters. Hydraulic: each droplet starts at a random point, follows the slope
 * with inertia, carries sediment up to capacity = max(-dh, min_slope) * speed * water *
 * capacity, erodes (spread over a radius) when below capacity and deposits when above or
 * going uphill, evaporates, and dies after max_steps or when it would leave the grid (its
 * sediment leaves with it). No cell is eroded below the lowest starting height (the base
 * level), and the sediment picked up is exactly the material removed. Thermal: material above the talus
 * slope moves to lower neighbours. */
typedef struct ak_terrain_erosion {
    uint32_t droplets;       /* hydraulic droplets; 0 -> no hydraulic pass */
    uint32_t thermal_iterations; /* thermal passes over the grid; 0 -> none */
    uint64_t seed;           /* droplet start points (ak_rng) */
    float inertia;           /* 0..1 share of the old direction kept per step; 0 -> 0.05 */
    float capacity;          /* sediment capacity factor; 0 -> 4 */
    float deposition;        /* 0..1 share of excess sediment dropped per step; 0 -> 0.3 */
    float erosion;           /* 0..1 share of the capacity deficit taken per step; 0 -> 0.3 */
    float evaporation;       /* 0..1 water lost per step; 0 -> 0.01 */
    float min_slope;         /* in metres per cell; 0 -> 0.01 */
    uint32_t max_steps;      /* per droplet, at most 4096; 0 -> 64 */
    uint32_t radius;         /* erosion brush radius in cells, at most 8; 0 -> 3 */
    float talus;             /* thermal: critical height difference per cell as a share of
                                the cell size; 0 -> 0.8 */
} ak_terrain_erosion;

/* Run the passes in place on heights (count >= width * height). Heights stay finite.
 * AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (desc, or a parameter out of range), AK_ERR_SPAN_SMALL,
 * AK_ERR_BAD_DATA (a non-finite height: nothing changed). progress (may be NULL) is called
 * with (done, total) now and then, for a progress bar. */
AK_API ak_result ak_terrain_erode(const ak_terrain_erosion* erosion, const ak_terrain_desc* desc, ak_f32_span heights,
                                  void (*progress)(size_t done, size_t total, void* user), void* user);

/* Colours (sRGB, alpha 1) by height and slope: water-level sand, grass on gentle slopes, rock
 * on steep ones (slope from the normal), snow on high gentle ground. heights/normals/out
 * counts >= width * height. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_terrain_colors(const ak_terrain_desc* desc, ak_f32_cspan heights, ak_vec3_cspan normals,
                                   ak_vec4_span out_colors);

/* Index count of the mesh: (width - 1) * (height - 1) * 6 (two counter-clockwise triangles
 * per cell, seen from +y). 0 for a bad desc. */
AK_API size_t ak_terrain_index_count(const ak_terrain_desc* desc);

/* Mesh positions (world, see Layout), UVs (u = i / (width - 1), v = j / (height - 1)) and
 * indices. out_uvs and out_indices may be empty (not written). AK_ERR_NULL_ARG,
 * AK_ERR_BAD_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_terrain_mesh(const ak_terrain_desc* desc, ak_f32_cspan heights, ak_vec3_span out_positions,
                                 ak_vec2_span out_uvs, ak_u32_span out_indices);

/* Write the heightfield as Wavefront OBJ (v, vt, vn, f v/vt/vn). AK_ERR_IO on a write error,
 * AK_ERR_NULL_ARG / AK_ERR_BAD_ARG / AK_ERR_SPAN_SMALL for bad arguments. Both writers here
 * write whole files or nothing: a temporary ".NAME.XXXXXX" beside path is renamed over it
 * once complete; on a failure it is removed and path is left untouched. */
AK_API ak_result ak_terrain_write_obj(const char* path, const ak_terrain_desc* desc, ak_f32_cspan heights,
                                      ak_vec3_cspan normals);

/* Write a 16-bit greyscale PNG (width x height, row j = image row j): value
 * round((h - lo) / (hi - lo) * 65535), clamped. lo == hi == 0 -> the heights' own min and max
 * (a flat field writes 0). AK_ERR_IO, AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (lo > hi, non-finite),
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_terrain_write_png16(const char* path, const ak_terrain_desc* desc, ak_f32_cspan heights, float lo,
                                        float hi);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_TERRAIN_H */
