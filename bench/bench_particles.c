/* Particle step and neighbour-grid timings, with the machine's triad bandwidth measured in the
 * same run so the "% of triad" figures carry over between machines.
 *
 *   1. 1,000,000 particles, semi-implicit Euler, gravity + linear and quadratic drag + one
 *      plane collision per step: particles per second on 1 and 2 threads, and the bytes the
 *      step moves (64 per particle: reads position, velocity, inverse mass, age, lifetime;
 *      writes position, velocity, age) as a percentage of the triad on as many threads.
 *   2. Neighbour grid at 100,000 points (about 20 neighbours each): build time, all pairs
 *      closer than r on 1 and 2 threads (pairs per second), and at 10,000 points the time of a
 *      brute-force double loop over the grid's (build + pairs) time.
 *
 * One-thread figures use the thread's CPU time (on a loaded machine, closer to what an idle
 * core takes), two-thread figures wall time; best of several repetitions each.
 * Usage: bench_particles [particle_count]. */
#include <animkit/animkit.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_clock.h"

#define STEP_BYTES 64.0

/* CPU time of this thread for single-threaded runs, wall time for multi-threaded ones. */
static double clock_s(uint32_t threads) { return threads > 1 ? bench_wall_s() : bench_cpu_s(); }

/* ---- STREAM-like triad a = b + s c (12 bytes per element), on 1 or 2 threads ---------- */

typedef struct triad_part {
    float *a, *b, *c;
    size_t n;
    float s;
} triad_part;

static void* triad_thread(void* arg) {
    triad_part* t = (triad_part*)arg;
    for (size_t i = 0; i < t->n; ++i) t->a[i] = t->b[i] + t->s * t->c[i];
    return NULL;
}

static double triad_gbps(int threads) {
    const size_t n = (size_t)16 << 20;
    float* a = (float*)malloc(n * sizeof(float));
    float* b = (float*)malloc(n * sizeof(float));
    float* c = (float*)malloc(n * sizeof(float));
    if (!a || !b || !c) {
        printf("out of memory\n");
        exit(1);
    }
    for (size_t i = 0; i < n; ++i) a[i] = 0.0f, b[i] = (float)(i & 1023), c[i] = 1.0f;
    double best = 1e30;
    for (int rep = 0; rep < 8; ++rep) {
        const float s = 1.0f + 1e-3f * (float)rep;
        triad_part p0 = {a, b, c, threads == 2 ? n / 2 : n, s};
        triad_part p1 = {a + n / 2, b + n / 2, c + n / 2, n - n / 2, s};
        double t0 = clock_s((uint32_t)threads);
        pthread_t id;
        bool started = threads == 2 && pthread_create(&id, NULL, triad_thread, &p1) == 0;
        triad_thread(&p0);
        if (started)
            pthread_join(id, NULL);
        else if (threads == 2)
            triad_thread(&p1);
        double t = clock_s((uint32_t)threads) - t0;
        if (t < best) best = t;
    }
    volatile float sink = a[n / 3];
    (void)sink;
    free(a), free(b), free(c);
    return 12.0 * (double)n / best * 1e-9;
}

/* ---- particle step ------------------------------------------------------------------- */

static double step_rate(size_t n, uint32_t threads) {
    ak_particles* ps = NULL;
    ak_particles_desc d = {.capacity = (uint32_t)n, .thread_count = threads, .seed = 1};
    if (ak_particles_create(&d, NULL, &ps) != AK_OK) {
        printf("cannot create %zu particles\n", n);
        exit(1);
    }
    ak_rng rng = ak_rng_make(7);
    for (size_t i = 0; i < n; ++i) {
        ak_particle_init in = {.position = {ak_rng_range(&rng, -10, 10), ak_rng_range(&rng, 0, 20),
                                            ak_rng_range(&rng, -10, 10)},
                               .velocity = {ak_rng_range(&rng, -2, 2), ak_rng_range(&rng, -2, 2),
                                            ak_rng_range(&rng, -2, 2)},
                               .mass = 1.0f};
        ak_particles_add(ps, &in, NULL);
    }
    ak_particle_plane floor = {.normal = {0, 1, 0}, .restitution = 0.5f, .friction = 0.2f};
    ak_particles_world w = {.gravity = {0, -9.81f, 0},
                            .drag_linear = 0.1f,
                            .drag_quadratic = 0.01f,
                            .planes = {&floor, 1}};
    double best = 1e30;
    for (int s = 0; s < 14; ++s) {
        double t0 = clock_s(threads);
        ak_particles_step(ps, &w, 0.01f);
        double t = clock_s(threads) - t0;
        if (s >= 2 && t < best) best = t;
    }
    if (ak_particles_count(ps) != n) printf("  (lost particles: %zu)\n", ak_particles_count(ps));
    ak_particles_destroy(ps);
    return (double)n / best;
}

/* ---- grid ---------------------------------------------------------------------------- */

static ak_vec3* cloud(size_t n, float side, uint64_t seed) {
    ak_vec3* p = (ak_vec3*)malloc(n * sizeof *p);
    ak_rng rng = ak_rng_make(seed);
    for (size_t i = 0; i < n; ++i)
        p[i] = ak_vec3_make(ak_rng_range(&rng, 0, side), ak_rng_range(&rng, 0, side),
                            ak_rng_range(&rng, 0, side));
    return p;
}

typedef struct grid_times {
    double build_s, pairs_s[2], pairs2_cpu_s;
    size_t pairs;
} grid_times;

static grid_times grid_run(const ak_vec3* p, size_t n, float r, int reps) {
    grid_times gt = {1e30, {1e30, 1e30}, 1e30, 0};
    ak_grid_desc gd = {.cell_size = r};
    size_t bytes = ak_grid_memory_size(n, &gd);
    uint8_t* mem = (uint8_t*)malloc(bytes);
    ak_grid g;
    for (int k = 0; k < reps; ++k) {
        double t0 = clock_s(1);
        ak_grid_build(&gd, (ak_vec3_cspan){p, n}, (ak_u8_span){mem, bytes}, &g);
        double t = clock_s(1) - t0;
        if (t < gt.build_s) gt.build_s = t;
    }
    size_t count = 0;
    ak_grid_pairs_job job = {.grid = &g, .radius = r, .out_pair_count = &count};
    ak_grid_pairs_run(&job); /* count */
    /* A quarter of slack, so no thread overflows its share and runs twice. */
    const size_t cap = count + count / 4 + 64;
    ak_grid_pair* pairs = (ak_grid_pair*)malloc(cap * sizeof *pairs);
    job.out_pairs = (ak_grid_pair_span){pairs, cap};
    for (uint32_t th = 1; th <= 2; ++th) {
        job.thread_count = th;
        for (int k = 0; k < reps; ++k) {
            double t0 = clock_s(th), p0 = bench_proc_s();
            ak_grid_pairs_run(&job);
            double t = clock_s(th) - t0, pc = bench_proc_s() - p0;
            if (t < gt.pairs_s[th - 1]) gt.pairs_s[th - 1] = t;
            if (th == 2 && pc < gt.pairs2_cpu_s) gt.pairs2_cpu_s = pc;
        }
    }
    gt.pairs = count;
    free(pairs);
    free(mem);
    return gt;
}

static double brute_pairs_s(const ak_vec3* p, size_t n, float r, size_t* out_count) {
    const float r2 = r * r;
    double best = 1e30;
    for (int k = 0; k < 3; ++k) {
        size_t count = 0;
        double t0 = clock_s(1);
        for (size_t i = 0; i < n; ++i)
            for (size_t j = i + 1; j < n; ++j) {
                float dx = p[j].x - p[i].x, dy = p[j].y - p[i].y, dz = p[j].z - p[i].z;
                count += dx * dx + dy * dy + dz * dz < r2;
            }
        double t = clock_s(1) - t0;
        if (t < best) best = t;
        *out_count = count;
    }
    return best;
}

int main(int argc, char** argv) {
    size_t n = argc > 1 ? (size_t)strtoul(argv[1], NULL, 10) : 1000000;
    if (n == 0) n = 1000000;
    const double triad1 = triad_gbps(1), triad2 = triad_gbps(2);
    printf("triad: %.1f GB/s (1 thread), %.1f GB/s (2 threads)\n", triad1, triad2);

    printf("\nparticle step: %zu particles, semi-implicit Euler, gravity + drag + 1 plane, %.0f "
           "bytes each\n",
           n, STEP_BYTES);
    for (uint32_t th = 1; th <= 2; ++th) {
        double rate = step_rate(n, th);
        double gbs = rate * STEP_BYTES * 1e-9;
        printf("  %u thread%s: %7.1f M particles/s  %5.1f GB/s  = %3.0f%% of the %u-thread triad\n",
               th, th > 1 ? "s" : " ", rate * 1e-6, gbs, 100.0 * gbs / (th == 1 ? triad1 : triad2),
               th);
    }

    /* Side chosen so each point has about 20 neighbours within r: n (4/3 pi r^3) / side^3. */
    const float r = 0.363f;
    const size_t big = 100000, small = 10000;
    ak_vec3* p = cloud(big, 10.0f, 11);
    grid_times gt = grid_run(p, big, r, 5);
    printf("\ngrid: %zu points, r = cell = %.3f, %zu pairs (%.1f neighbours each)\n", big,
           (double)r, gt.pairs, 2.0 * (double)gt.pairs / (double)big);
    printf("  build: %.2f ms (%.1f M points/s)\n", gt.build_s * 1e3,
           (double)big / gt.build_s * 1e-6);
    for (int th = 0; th < 2; ++th)
        printf("  all pairs, %d thread%s: %.2f ms  %.1f M pairs/s\n", th + 1, th ? "s" : " ",
               gt.pairs_s[th] * 1e3, (double)gt.pairs / gt.pairs_s[th] * 1e-6);
    printf(
        "  (2 threads: %.2f ms of CPU time over both, vs %.2f ms on one: the work does not grow)\n",
        gt.pairs2_cpu_s * 1e3, gt.pairs_s[0] * 1e3);
    free(p);

    p = cloud(small, 10.0f * 0.46416f, 12); /* same density */
    grid_times gs = grid_run(p, small, r, 9);
    size_t brute_count = 0;
    double brute = brute_pairs_s(p, small, r, &brute_count);
    double grid_total = gs.build_s + gs.pairs_s[0];
    printf("  at %zu points: brute force %.2f ms, grid build + pairs %.3f ms (1 thread): grid "
           "%.0fx faster%s\n",
           small, brute * 1e3, grid_total * 1e3, brute / grid_total,
           brute_count == gs.pairs ? "" : "  (PAIR COUNTS DIFFER)");
    free(p);
    return 0;
}
