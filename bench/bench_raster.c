/* bench_raster: 640x480 frames of a 50,000-triangle torus knot-ish mesh (a torus with a wavy
 * tube) filling most of the frame. Times clear + draw + resolve per frame for flat, Gouraud and
 * Phong shading with 1 and 2 threads, supersampling 2x2 with Phong, and Phong with a 512x512
 * base-colour texture (bilinear and nearest, REPEAT, the UVs tiling it 2 x 1 times over the
 * torus); prints absolute
 * frame times and ratios measured in the same run. Fixed geometry, no randomness. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_clock.h"

#include <animkit/raster.h>

enum { SEG_U = 250, SEG_V = 100 }; /* 250 * 100 * 2 = 50,000 triangles */

typedef struct timing {
    double wall_ms, cpu_ms; /* medians per frame; cpu is the calling thread only */
    double proc_ms;         /* median CPU time of all threads per frame */
} timing;

static void make_mesh(ak_vec3* pos, ak_vec3* nrm, ak_vec2* uv, uint32_t* idx) {
    for (int i = 0; i <= SEG_U; ++i)
        for (int j = 0; j <= SEG_V; ++j) {
            float u = AK_TWO_PI * (float)i / SEG_U, v = AK_TWO_PI * (float)j / SEG_V;
            float tube = 0.32f + 0.05f * sinf(7.0f * u);
            ak_vec3 c = ak_vec3_make(cosf(u), 0.15f * sinf(3.0f * u), sinf(u));
            ak_vec3 n = ak_vec3_make(cosf(v) * cosf(u), sinf(v), cosf(v) * sinf(u));
            pos[i * (SEG_V + 1) + j] = ak_vec3_add(c, ak_vec3_scale(n, tube));
            nrm[i * (SEG_V + 1) + j] = n; /* approximate normal is fine for timing */
            uv[i * (SEG_V + 1) + j] = ak_vec2_make(2.0f * (float)i / SEG_U, (float)j / SEG_V);
        }
    size_t k = 0;
    for (int i = 0; i < SEG_U; ++i)
        for (int j = 0; j < SEG_V; ++j) {
            uint32_t a = (uint32_t)(i * (SEG_V + 1) + j), b = a + SEG_V + 1;
            idx[k++] = a, idx[k++] = a + 1, idx[k++] = b;
            idx[k++] = b, idx[k++] = a + 1, idx[k++] = b + 1;
        }
}

/* Median milliseconds per frame over reps frames. */
static timing time_frames(int threads, int ss, ak_shading shading, const ak_raster_mesh* base, int reps,
                          const char* png) {
    const int W = 640, H = 480;
    ak_raster* r = NULL;
    if (ak_raster_create(&(ak_raster_desc){.width = W, .height = H, .supersample = ss, .thread_count = threads}, NULL,
                         &r) != AK_OK)
        return (timing){-1, -1, -1};
    uint8_t* px = malloc((size_t)W * H * 4);
    ak_image img = {.pixels = px, .width = W, .height = H};
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0.0f, 1.6f, 2.2f), ak_vec3_make(0, -0.05f, 0),
                                                        ak_radians(45), (float)W / H, 0.1f, 20);
    ak_raster_mesh m = *base;
    m.shading = shading;
    double tw[64], tc[64], tp[64];
    for (int i = 0; i < reps; ++i) {
        double t0 = bench_wall_s(), c0 = bench_cpu_s(), p0 = bench_proc_s();
        ak_raster_clear(r, ak_vec4_make(0.82f, 0.86f, 0.92f, 1), ak_vec4_make(0.5f, 0.52f, 0.58f, 1));
        ak_raster_draw_mesh(r, &cam, &m);
        ak_raster_resolve(r, &img);
        tw[i] = (bench_wall_s() - t0) * 1e3;
        tc[i] = (bench_cpu_s() - c0) * 1e3;
        tp[i] = (bench_proc_s() - p0) * 1e3;
    }
    if (png) ak_png_write(png, &img);
    ak_raster_destroy(r);
    free(px);
    return (timing){bench_percentile(tw, (size_t)reps, 0.5), bench_percentile(tc, (size_t)reps, 0.5), bench_percentile(tp, (size_t)reps, 0.5)};
}

int main(int argc, char** argv) {
    const size_t nv = (SEG_U + 1) * (SEG_V + 1), ni = SEG_U * SEG_V * 6;
    ak_vec3* pos = malloc(nv * sizeof *pos);
    ak_vec3* nrm = malloc(nv * sizeof *nrm);
    ak_vec2* uv = malloc(nv * sizeof *uv);
    uint32_t* idx = malloc(ni * sizeof *idx);
    enum { TS = 512 };
    uint8_t* texels = malloc((size_t)TS * TS * 4);
    if (!pos || !nrm || !uv || !idx || !texels) return 1;
    make_mesh(pos, nrm, uv, idx);
    for (int y = 0; y < TS; ++y)
        for (int x = 0; x < TS; ++x) {
            uint8_t* t = texels + ((size_t)y * TS + (size_t)x) * 4;
            t[0] = (uint8_t)(x ^ y), t[1] = (uint8_t)(2 * x), t[2] = (uint8_t)(3 * y), t[3] = 255;
        }
    ak_raster_mesh m = {.positions = {pos, nv}, .normals = {nrm, nv}, .indices = {idx, ni}, .cull_back_faces = true};
    const int reps = 21;
    const char* png = argc > 1 ? argv[1] : NULL; /* optional: write the Phong frame for a look */
    printf("bench_raster: 640x480, %zu triangles, median of %d frames (clear + draw + resolve)\n", ni / 3, reps);
    timing flat1 = time_frames(1, 1, AK_SHADING_FLAT, &m, reps, NULL);
    timing gour1 = time_frames(1, 1, AK_SHADING_GOURAUD, &m, reps, NULL);
    timing phong1 = time_frames(1, 1, AK_SHADING_PHONG, &m, reps, png);
    timing phong2 = time_frames(2, 1, AK_SHADING_PHONG, &m, reps, NULL);
    timing flat2 = time_frames(2, 1, AK_SHADING_FLAT, &m, reps, NULL);
    timing ss1 = time_frames(1, 2, AK_SHADING_PHONG, &m, reps / 2, NULL);
    ak_raster_texture tex = {.image = {.pixels = texels, .width = TS, .height = TS}};
    ak_raster_mesh mt = m;
    mt.uvs = (ak_vec2_cspan){uv, nv};
    mt.texture = &tex;
    timing tex_lin = time_frames(1, 1, AK_SHADING_PHONG, &mt, reps, NULL);
    tex.mag_filter = tex.min_filter = AK_RASTER_FILTER_NEAREST;
    timing tex_near = time_frames(1, 1, AK_SHADING_PHONG, &mt, reps, NULL);
    printf("                      wall ms   1-thread CPU ms\n");
    printf("  flat     1 thread : %7.2f   %7.2f\n", flat1.wall_ms, flat1.cpu_ms);
    printf("  gouraud  1 thread : %7.2f   %7.2f\n", gour1.wall_ms, gour1.cpu_ms);
    printf("  phong    1 thread : %7.2f   %7.2f   (target <= 20 ms on one core)\n", phong1.wall_ms, phong1.cpu_ms);
    printf("  phong    2 threads: %7.2f   (all threads: %.2f CPU ms)\n", phong2.wall_ms, phong2.proc_ms);
    printf("  flat     2 threads: %7.2f   (all threads: %.2f CPU ms)\n", flat2.wall_ms, flat2.proc_ms);
    printf("  phong SSAA 2x2 1t : %7.2f   %7.2f\n", ss1.wall_ms, ss1.cpu_ms);
    printf("  phong textured 1t : %7.2f   %7.2f   (bilinear)\n", tex_lin.wall_ms, tex_lin.cpu_ms);
    printf("  phong textured 1t : %7.2f   %7.2f   (nearest)\n", tex_near.wall_ms, tex_near.cpu_ms);
    printf("  phong throughput  : %.2f Mtri/s (CPU time)\n", 0.05 / phong1.cpu_ms * 1e3);
    printf("ratios (CPU time): phong/flat %.2f, gouraud/flat %.2f, SSAA2x2/phong %.2f\n", phong1.cpu_ms / flat1.cpu_ms,
           gour1.cpu_ms / flat1.cpu_ms, ss1.cpu_ms / phong1.cpu_ms);
    printf("ratios (CPU time): textured/phong bilinear %.2f, nearest %.2f\n", tex_lin.cpu_ms / phong1.cpu_ms,
           tex_near.cpu_ms / phong1.cpu_ms);
    printf("ratios (wall): phong 1t/2t %.2f, flat 1t/2t %.2f\n", phong1.wall_ms / phong2.wall_ms,
           flat1.wall_ms / flat2.wall_ms);
    /* total work with 2 threads over 1 (1.0 = no overhead): the redundant per-thread setup */
    printf("work overhead of 2 threads (CPU all threads / CPU 1 thread): phong %.2f, flat %.2f\n",
           phong2.proc_ms / phong1.cpu_ms, flat2.proc_ms / flat1.cpu_ms);
    free(pos);
    free(nrm);
    free(uv);
    free(texels);
    free(idx);
    return 0;
}
