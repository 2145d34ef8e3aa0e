/* Fluid benchmark: a dam break of N particles (default 50,000), ms per step for SPH, WCSPH and
 * PBF (4 iterations) on 1 and 2 threads, the neighbour-search share, particles per second.
 *     bench_fluid [N] [STEPS]
 * Each configuration starts from the same block, runs 5 warm-up steps then STEPS timed steps
 * (default 10); wall and process CPU time are both printed (the machine may be shared). */
#include <animkit/fluid.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

typedef struct result {
    double wall_ms, cpu_ms, nb_ms;
    size_t count;
} result;

static result run(ak_fluid_solver solver, uint32_t threads, size_t want, int steps) {
    ak_fluid_desc d = {.solver = solver, .particle_mass = 0.001f, .gravity = {0, -9.81f, 0}, .xsph_c = 0.01f,
                       .vorticity_epsilon = solver == AK_FLUID_PBF ? 0.1f : 0.0f, .iterations = 4,
                       .viscosity = solver == AK_FLUID_WCSPH ? 0.05f : 0.02f};
    const float s = ak_fluid_rest_spacing(&d);
    d.h = 2.0f * s;
    /* block of 2:2:1 proportions holding about `want` particles, in a box 2x as long */
    int side = 1;
    while ((size_t)(2 * side) * (2 * side) * side < want) ++side;
    const float bx = 2.0f * side * s, by = 2.0f * side * s, bz = side * s;
    d.box_max = ak_vec3_make(2.5f * bx, 1.5f * by, bz);
    size_t cap = (size_t)(2 * side) * (2 * side) * side;
    ak_vec3* pos = malloc(cap * sizeof *pos);
    ak_vec3* vel = calloc(cap, sizeof *vel);
    size_t n = ak_fluid_fill_box(&d, d.box_min, ak_vec3_make(bx, by, bz), (ak_vec3_span){pos, cap});
    size_t bytes = ak_fluid_scratch_size(n, &d);
    void* mem = malloc(bytes);
    ak_fluid_stats st;
    ak_fluid_step_job job = {.desc = &d, .dt = solver == AK_FLUID_PBF ? 1.0f / 400.0f : 2e-4f,
                             .positions = {pos, n}, .velocities = {vel, n}, .particle_count = &n,
                             .thread_count = threads, .scratch = {mem, bytes}, .out_stats = &st};
    for (int k = 0; k < 5; ++k) ak_fluid_step_run(&job);
    double nb = 0.0, w0 = bench_wall_s(), c0 = bench_proc_s();
    for (int k = 0; k < steps; ++k) {
        if (ak_fluid_step_run(&job) != AK_OK) fprintf(stderr, "step %d failed\n", k);
        nb += st.neighbour_seconds;
    }
    result r = {(bench_wall_s() - w0) * 1e3 / steps, (bench_proc_s() - c0) * 1e3 / steps, nb * 1e3 / steps, n};
    free(pos), free(vel), free(mem);
    return r;
}

int main(int argc, char** argv) {
    size_t want = argc > 1 ? (size_t)atol(argv[1]) : 50000;
    int steps = argc > 2 ? atoi(argv[2]) : 10;
    if (want < 8 || steps < 1) return 2;
    const char* names[] = {"PBF (4 it)", "SPH", "WCSPH"};
    const ak_fluid_solver solvers[] = {AK_FLUID_PBF, AK_FLUID_SPH, AK_FLUID_WCSPH};
    printf("dam break, at least %zu particles, h = 2 x spacing, %d timed steps (cpu = all threads)\n", want, steps);
    printf("%-11s %7s %9s %10s %10s %9s %10s %12s\n", "solver", "threads", "particles", "wall ms", "cpu ms", "nb ms",
           "nb share", "particles/s");
    for (int k = 0; k < 3; ++k) {
        result one = {0}, two = {0};
        for (uint32_t t = 1; t <= 2; ++t) {
            result r = run(solvers[k], t, want, steps);
            if (t == 1) one = r;
            else two = r;
            printf("%-11s %7u %9zu %10.2f %10.2f %9.2f %9.0f%% %12.3g\n", names[k], t, r.count, r.wall_ms, r.cpu_ms,
                   r.nb_ms, 100.0 * r.nb_ms / r.wall_ms, (double)r.count / (r.wall_ms * 1e-3));
        }
        printf("%-11s 2 vs 1 thread: wall %.2fx, cpu per particle-step %.0f ns (1 thread)\n", names[k],
               one.wall_ms / two.wall_ms, one.cpu_ms * 1e6 / (double)one.count);
    }
    return 0;
}
