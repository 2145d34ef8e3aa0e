/* bench_sprites: camera-facing textured sprites (ak_raster_draw_sprites) against round points
 * (ak_raster_draw_points) for the same particles, 640x480, one thread. A fixed cloud of N
 * particles (a smoke column: a Gaussian blob 1 m across seen from 3 m) drawn as 64x64 puff
 * sprites of 0.08 m, alpha-blended after a back-to-front sort (ak_raster_sprites_sort) or
 * additive; points of the same projected radius. Prints the median milliseconds per draw
 * (calling-thread CPU time) and the ratios sprites/points and sort/draw measured side by side. */
#include <stdio.h>
#include <stdlib.h>

#include "bench_clock.h"

#include <animkit/raster.h>

enum { W = 640, H = 480, REPS = 15 };

typedef struct cloud {
    ak_vec3* pos;
    ak_vec4* col;
    float* depth;
    uint32_t* order;
    size_t n;
} cloud;

/* Deterministic Gaussian-ish points (sum of three uniforms from an LCG). */
static float lcg(uint32_t* s) {
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) * (1.0f / 16777216.0f);
}

static void cloud_make(cloud* c, size_t n) {
    c->n = n;
    c->pos = malloc(n * sizeof *c->pos), c->col = malloc(n * sizeof *c->col);
    c->depth = malloc(n * sizeof *c->depth), c->order = malloc(n * sizeof *c->order);
    uint32_t s = 12345u;
    for (size_t i = 0; i < n; ++i) {
        float g[3];
        for (int k = 0; k < 3; ++k) g[k] = (lcg(&s) + lcg(&s) + lcg(&s) - 1.5f) * 0.6f;
        c->pos[i] = ak_vec3_make(g[0], 1.0f + 1.5f * g[1], g[2]);
        c->col[i] = ak_vec4_make(0.6f, 0.6f, 0.62f, 0.3f);
    }
}

static void cloud_free(cloud* c) { free(c->pos), free(c->col), free(c->depth), free(c->order); }

typedef enum what { POINTS, SPRITES_ALPHA, SPRITES_ADD, SORT_ONLY } what;

static double time_draw(ak_raster* r, const ak_raster_camera* cam, cloud* c, const ak_image* tex, what w) {
    double t[REPS];
    for (int i = 0; i < REPS; ++i) {
        ak_raster_clear(r, ak_vec4_make(0.82f, 0.86f, 0.92f, 1), ak_vec4_make(0.5f, 0.52f, 0.58f, 1));
        double c0 = bench_cpu_s();
        if (w == POINTS) {
            ak_raster_points p = {.positions = {c->pos, c->n}, .colors = {c->col, c->n}, .radius = 5.0f};
            ak_raster_draw_points(r, cam, &p);
        } else {
            if (w != SPRITES_ADD)
                ak_raster_sprites_sort(cam, (ak_vec3_cspan){c->pos, c->n}, (ak_f32_span){c->depth, c->n},
                                       (ak_u32_span){c->order, c->n});
            if (w != SORT_ONLY) {
                ak_raster_sprites s = {.positions = {c->pos, c->n}, .colors = {c->col, c->n}, .size = 0.08f,
                                       .texture = tex, .blend = w == SPRITES_ADD ? AK_BLEND_ADD : AK_BLEND_ALPHA};
                if (w == SPRITES_ALPHA) s.order = (ak_u32_cspan){c->order, c->n};
                ak_raster_draw_sprites(r, cam, &s);
            }
        }
        t[i] = (bench_cpu_s() - c0) * 1e3;
    }
    return bench_percentile(t, REPS, 0.5);
}

int main(void) {
    ak_raster* r = NULL;
    if (ak_raster_create(&(ak_raster_desc){.width = W, .height = H}, NULL, &r) != AK_OK) return 1;
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 1.2f, 3.0f), ak_vec3_make(0, 1.0f, 0),
                                                        ak_radians(45), (float)W / H, 0.1f, 20);
    static uint8_t tex_px[64 * 64 * 4];
    ak_image tex = {.pixels = tex_px, .width = 64, .height = 64};
    ak_sprite_texture_generate(AK_SPRITE_TEXTURE_PUFF, 1, &tex);
    printf("bench_sprites: %dx%d, 1 thread, 0.08 m puff sprites (about 14 px) vs 5 px points, median of %d draws "
           "(calling-thread CPU ms)\n", W, H, REPS);
    printf("  particles   points   sprites(alpha,sorted)   sprites(add)   sort only   sprites/points   sort/alpha-draw   "
           "Msprites/s(alpha)\n");
    const size_t counts[3] = {1000, 10000, 50000};
    for (int k = 0; k < 3; ++k) {
        cloud c;
        cloud_make(&c, counts[k]);
        double pt = time_draw(r, &cam, &c, &tex, POINTS), al = time_draw(r, &cam, &c, &tex, SPRITES_ALPHA);
        double ad = time_draw(r, &cam, &c, &tex, SPRITES_ADD), so = time_draw(r, &cam, &c, &tex, SORT_ONLY);
        printf("  %9zu %8.2f %23.2f %14.2f %11.2f %16.2f %17.2f %19.2f\n", c.n, pt, al, ad, so, al / pt, so / al,
               (double)c.n / al * 1e-3);
        cloud_free(&c);
    }
    ak_raster_destroy(r);
    return 0;
}
