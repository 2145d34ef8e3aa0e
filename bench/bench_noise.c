/* bench_noise: 3D Perlin and simplex samples per second through the batch job, scalar, AVX2 and
 * AVX-512 side by side (values only, and values + gradient), plus the plain per-point call; and a 1024x1024
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
                         ak_noise_basis basis, ak_noise_simd lim, bool grad) {
    double t[REPS];
    for (int r = 0; r < REPS; ++r) {
        ak_noise_job job = {.noise = n, .fractal = {.octaves = 1, .basis = basis}, .dimensions = 3, .x = {x, N},
                            .y = {y, N}, .z = {z, N}, .out_values = {out, N}, .simd_limit = lim};
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
    /* simd: the widest kernel this CPU has */
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
    printf("bench_noise: widest SIMD kernel %s (AVX-512 rows run AVX2 where the CPU lacks it)\n", ak_noise_simd_name());

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
    printf("\n3D noise, 2^20 random points in [-100, 100]^3, 1 thread (CPU time, median of %d)\n", REPS);
    printf("  %-34s %8.1f M samples/s\n", "ak_noise_perlin3 per point", point_rate / 1e6);
    const ak_noise_basis bases[2] = {AK_NOISE_BASIS_PERLIN, AK_NOISE_BASIS_SIMPLEX};
    const char* names[2] = {"Perlin", "simplex"};
    double perlin_best = 0.0;
    for (int b = 0; b < 2; ++b)
        for (int gr = 0; gr < 2; ++gr) {
            const double sc = batch_rate(&n, x, y, z, out, g, bases[b], AK_NOISE_SIMD_SCALAR, gr);
            const double a2 = batch_rate(&n, x, y, z, out, g, bases[b], AK_NOISE_SIMD_AVX2, gr);
            const double a5 = batch_rate(&n, x, y, z, out, g, bases[b], AK_NOISE_SIMD_AVX512, gr);
            if (b == 0 && gr == 0) perlin_best = a5 > a2 ? a5 : a2;
            printf("  %-7s batch job, %-14s scalar %6.1f  AVX2 %6.1f  AVX-512 %6.1f M samples/s"
                   "   AVX2/scalar %.2fx  AVX-512/AVX2 %.2fx\n",
                   names[b], gr ? "value+gradient" : "value", sc / 1e6, a2 / 1e6, a5 / 1e6, a2 / sc, a5 / a2);
        }
    printf("  widest batch (Perlin value) vs ak_noise_perlin3 per point: %.2fx\n", perlin_best / point_rate);

    float* h = malloc(sizeof(float) * 1024 * 1024 * 3);
    if (!h) return 1;
    const double s1 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 1, false);
    const double v1 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 1, true);
    const double s2 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 2, false), s2c = last_proc_ms;
    const double v2 = terrain_ms(&n, h, h + 1024 * 1024, h + 2 * 1024 * 1024, 2, true), v2c = last_proc_ms;
    printf("\n1024x1024 heightfield, 8-octave fBm (2D Perlin) with gradient (grid job, median of %d)\n", REPS);
    printf("  1 thread : scalar %8.1f ms   SIMD %8.1f ms   ratio %.2fx\n", s1, v1, s1 / v1);
    printf("  2 threads: scalar %8.1f ms   SIMD %8.1f ms   ratio %.2fx   (SIMD 1 -> 2 threads %.2fx, wall)\n", s2,
           v2, s2 / v2, v1 / v2);
    printf("             CPU of both threads: scalar %.1f ms, SIMD %.1f ms (a busy machine shows in wall >> CPU / 2)\n",
           s2c, v2c);
    ak_vec3* nrm = malloc(sizeof(ak_vec3) * 1024 * 1024);
    if (!nrm) return 1;
    const double g1 = terrain_generate_ms(&n, h, nrm, 1), g2 = terrain_generate_ms(&n, h, nrm, 2), g2c = last_proc_ms;
    printf("  ak_terrain_generate (heights + unit normals, SIMD): 1 thread %.1f ms, 2 threads %.1f ms wall (%.2fx),"
           " CPU of both %.1f ms\n", g1, g2, g1 / g2, g2c);
    free(nrm);
    free(h);
    free(x);
    return sink == 12345.0f;
}
