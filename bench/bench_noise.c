/* bench_noise: 3D Perlin samples per second through the batch job, scalar and AVX2 side by
 * side (values only, and values + gradient), plus the plain per-point call; and a 1024x1024
 * 8-octave fBm heightfield (grid job, values + gradient as terrain needs) on 1 and 2 threads.
 * Fixed seeds; medians of repeated runs; CPU time of the calling thread for the single-thread
 * rows (steadier on a shared machine), wall time for the threaded rows. */
#include <stdio.h>
#include <stdlib.h>

#include "bench_clock.h"

#include <animkit/terrain.h>

enum { N = 1 << 20, REPS = 7 };

static double median_of(double* v, int n) { return bench_percentile(v, (size_t)n, 0.5); }

static double batch_rate(const ak_noise* n, const float* x, const float* y, const float* z, float* out, float* g,
                         bool simd, bool grad) {
    double t[REPS];
    for (int r = 0; r < REPS; ++r) {
        ak_noise_job job = {.noise = n, .fractal = {.octaves = 1}, .dimensions = 3, .x = {x, N}, .y = {y, N},
                            .z = {z, N}, .out_values = {out, N}, .skip_simd = !simd};
        if (grad) {
            job.out_gradient_x = (ak_f32_span){g, N};
            job.out_gradient_y = (ak_f32_span){g + N, N};
            job.out_gradient_z = (ak_f32_span){g + 2 * N, N};
        }
        double t0 = bench_cpu_s();
        ak_noise_job_run(&job);
        t[r] = bench_cpu_s() - t0;
    }
    return N / median_of(t, REPS);
}

/* CPU time of all threads of the last timed multi-threaded run (median), ms. */
static double last_proc_ms;

static double terrain_ms(const ak_noise* n, float* h, float* gx, float* gy, uint32_t threads, bool simd) {
    double t[REPS], c[REPS];
    for (int r = 0; r < REPS; ++r) {
        ak_noise_grid_job job = {.noise = n, .fractal = {.type = AK_FRACTAL_FBM, .octaves = 8},
                                 .width = 1024, .height = 1024, .spacing_x = 8.0f / 1024, .spacing_y = 8.0f / 1024,
                                 .out_values = {h, 1024 * 1024}, .out_gradient_x = {gx, 1024 * 1024},
                                 .out_gradient_y = {gy, 1024 * 1024}, .thread_count = threads, .skip_simd = !simd};
        double t0 = threads > 1 ? bench_wall_s() : bench_cpu_s(), c0 = bench_proc_s();
        ak_noise_grid_job_run(&job);
        t[r] = (threads > 1 ? bench_wall_s() : bench_cpu_s()) - t0;
        c[r] = bench_proc_s() - c0;
    }
    last_proc_ms = 1e3 * median_of(c, REPS);
    return 1e3 * median_of(t, REPS);
}

static double terrain_generate_ms(const ak_noise* n, float* h, ak_vec3* nrm, uint32_t threads) {
    double t[REPS], c[REPS];
    for (int r = 0; r < REPS; ++r) {
        const ak_terrain_desc d = {.noise = n, .width = 1024, .height = 1024, .world_size = 1000, .height_scale = 100,
                                   .feature_size = 125, .fractal = {.octaves = 8}, .thread_count = threads};
        double t0 = threads > 1 ? bench_wall_s() : bench_cpu_s(), c0 = bench_proc_s();
        ak_terrain_generate(&d, (ak_f32_span){h, 1024 * 1024}, (ak_vec3_span){nrm, 1024 * 1024});
        t[r] = (threads > 1 ? bench_wall_s() : bench_cpu_s()) - t0;
        c[r] = bench_proc_s() - c0;
    }
    last_proc_ms = 1e3 * median_of(c, REPS);
    return 1e3 * median_of(t, REPS);
}

int main(void) {
    float* x = malloc(sizeof(float) * N * 7);
    if (!x) return 1;
    float *y = x + N, *z = x + 2 * N, *out = x + 3 * N, *g = x + 4 * N;
    ak_rng rng = ak_rng_make(1);
    for (size_t i = 0; i < 3 * (size_t)N; ++i) x[i] = ak_rng_range(&rng, -100.0f, 100.0f);
    ak_noise n = ak_noise_make(0);
    printf("bench_noise: AVX2 kernel %s\n", ak_noise_simd_available() ? "available" : "NOT available");

    /* the plain per-point function */
    double tp[REPS];
    volatile float sink = 0.0f;
    for (int r = 0; r < REPS; ++r) {
        double t0 = bench_cpu_s();
        float s = 0.0f;
        for (size_t i = 0; i < N; ++i) s += ak_noise_perlin3(&n, x[i], y[i], z[i], NULL);
        tp[r] = bench_cpu_s() - t0;
        sink += s;
    }
    const double point_rate = N / median_of(tp, REPS);
    const double sv = batch_rate(&n, x, y, z, out, g, false, false), vv = batch_rate(&n, x, y, z, out, g, true, false);
    const double sg = batch_rate(&n, x, y, z, out, g, false, true), vg = batch_rate(&n, x, y, z, out, g, true, true);
    printf("\n3D Perlin, 2^20 random points in [-100, 100]^3, 1 thread (CPU time, median of %d)\n", REPS);
    printf("  %-34s %8.1f M samples/s\n", "ak_noise_perlin3 per point", point_rate / 1e6);
    printf("  %-34s %8.1f M samples/s   AVX2 %8.1f M samples/s   ratio %.2fx\n", "batch job, value: scalar", sv / 1e6,
           vv / 1e6, vv / sv);
    printf("  %-34s %8.1f M samples/s   AVX2 %8.1f M samples/s   ratio %.2fx\n", "batch job, value+gradient: scalar",
           sg / 1e6, vg / 1e6, vg / sg);
    printf("  AVX2 batch (value) vs ak_noise_perlin3 per point: %.2fx\n", vv / point_rate);

    float* h = malloc(sizeof(float) * 1024 * 1024 * 3);
    if (!h) return 1;
    const double s1 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 1, false);
    const double v1 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 1, true);
    const double s2 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 2, false), s2c = last_proc_ms;
    const double v2 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 2, true), v2c = last_proc_ms;
    printf("\n1024x1024 heightfield, 8-octave fBm (2D Perlin) with gradient (grid job, median of %d)\n", REPS);
    printf("  1 thread : scalar %8.1f ms   AVX2 %8.1f ms   ratio %.2fx\n", s1, v1, s1 / v1);
    printf("  2 threads: scalar %8.1f ms   AVX2 %8.1f ms   ratio %.2fx   (AVX2 1 -> 2 threads %.2fx, wall)\n", s2,
           v2, s2 / v2, v1 / v2);
    printf("             CPU of both threads: scalar %.1f ms, AVX2 %.1f ms (a busy machine shows in wall >> CPU / 2)\n",
           s2c, v2c);
    ak_vec3* nrm = malloc(sizeof(ak_vec3) * 1024 * 1024);
    if (!nrm) return 1;
    const double g1 = terrain_generate_ms(&n, h, nrm, 1), g2 = terrain_generate_ms(&n, h, nrm, 2), g2c = last_proc_ms;
    printf("  ak_terrain_generate (heights + unit normals, AVX2): 1 thread %.1f ms, 2 threads %.1f ms wall (%.2fx),"
           " CPU of both %.1f ms\n", g1, g2, g1 / g2, g2c);
    free(nrm);
    free(h);
    free(x);
    return sink == 12345.0f;
}
