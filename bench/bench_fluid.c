/* Fluid benchmark: a dam break of N particles (default 50,000), ms per step for PBF (4
 * iterations), SPH and WCSPH on 1 and 2 threads, the neighbour-search share, particles per
 * second, for every kernel set this CPU runs (AVX-512, AVX2, scalar) side by side.
 *     bench_fluid [N] [STEPS] [ROUNDS] [pbf|sph|wcsph|all]
 * Each configuration starts from the same block, runs 5 warm-up steps then STEPS timed steps
 * (default 10); ROUNDS (default 3) repeats every configuration in turn (interleaved, so a load
 * change hits all of them alike) and the best round is printed. Wall and process CPU time are
 * both printed (the machine may be shared); each SIMD set's CPU time over scalar's on 1 and 2
 * threads is printed per solver (all three solvers have SIMD density and force/correction
 * passes). */
#include <animkit/fluid.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

typedef struct result {
    double wall_ms, cpu_ms, nb_ms;
    size_t count;
} result;

static result run(ak_fluid_solver solver, uint32_t threads, ak_fluid_kernels kernels, size_t want,
                  int steps) {
    ak_fluid_desc d = {.solver = solver,
                       .particle_mass = 0.001f,
                       .gravity = {0, -9.81f, 0},
                       .xsph_c = 0.01f,
                       .vorticity_epsilon = solver == AK_FLUID_PBF ? 0.1f : 0.0f,
                       .iterations = 4,
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
    ak_fluid_step_job job = {.desc = &d,
                             .dt = solver == AK_FLUID_PBF ? 1.0f / 400.0f : 2e-4f,
                             .positions = {pos, n},
                             .velocities = {vel, n},
                             .particle_count = &n,
                             .thread_count = threads,
                             .scratch = {mem, bytes},
                             .out_stats = &st,
                             .kernels = kernels};
    for (int k = 0; k < 5; ++k) ak_fluid_step_run(&job);
    double nb = 0.0, w0 = bench_wall_s(), c0 = bench_proc_s();
    for (int k = 0; k < steps; ++k) {
        if (ak_fluid_step_run(&job) != AK_OK) fprintf(stderr, "step %d failed\n", k);
        nb += st.neighbour_seconds;
    }
    result r = {(bench_wall_s() - w0) * 1e3 / steps, (bench_proc_s() - c0) * 1e3 / steps,
                nb * 1e3 / steps, n};
    free(pos), free(vel), free(mem);
    return r;
}

enum { SETS = 3, CONFIGS = 3 * SETS * 2 };

int main(int argc, char** argv) {
    size_t want = argc > 1 ? (size_t)atol(argv[1]) : 50000;
    int steps = argc > 2 ? atoi(argv[2]) : 10;
    int rounds = argc > 3 ? atoi(argv[3]) : 3;
    const char* only = argc > 4 ? argv[4] : "all";
    if (want < 8 || steps < 1 || rounds < 1) return 2;
    const char* names[] = {"PBF (4 it)", "SPH", "WCSPH"};
    const char* keys[] = {"pbf", "sph", "wcsph"};
    const ak_fluid_solver solvers[] = {AK_FLUID_PBF, AK_FLUID_SPH, AK_FLUID_WCSPH};
    /* the kernel sets this CPU runs, fastest first; scalar last */
    const ak_fluid_kernels sets[SETS] = {AK_FLUID_KERNELS_AVX512, AK_FLUID_KERNELS_AVX2,
                                         AK_FLUID_KERNELS_SCALAR};
    bool have[SETS];
    for (int k = 0; k < SETS; ++k) have[k] = ak_fluid_kernels_resolved(sets[k]) == sets[k];
    printf("dam break, at least %zu particles, h = 2 x spacing, %d timed steps, best of %d "
           "interleaved rounds\n"
           "(cpu = all threads; default kernels here: %s)\n",
           want, steps, rounds,
           ak_fluid_kernels_name(ak_fluid_kernels_resolved(AK_FLUID_KERNELS_BEST)));
    result best[CONFIGS];
    bool used[CONFIGS] = {false};
    for (int r = 0; r < rounds; ++r)
        for (int k = 0; k < 3; ++k) {
            if (strcmp(only, "all") != 0 && strcmp(only, keys[k]) != 0) continue;
            for (int sc = 0; sc < SETS; ++sc) {
                if (!have[sc]) continue;
                for (uint32_t t = 1; t <= 2; ++t) {
                    const int id = (k * SETS + sc) * 2 + (int)(t - 1);
                    result x = run(solvers[k], t, sets[sc], want, steps);
                    if (!used[id] || x.cpu_ms < best[id].cpu_ms) {
                        if (used[id] && x.wall_ms > best[id].wall_ms) x.wall_ms = best[id].wall_ms;
                        best[id] = x;
                    } else if (x.wall_ms < best[id].wall_ms) {
                        best[id].wall_ms = x.wall_ms;
                    }
                    used[id] = true;
                }
            }
        }
    printf("%-11s %-7s %7s %9s %10s %10s %9s %10s %12s\n", "solver", "kernels", "threads",
           "particles", "wall ms", "cpu ms", "nb ms", "nb share", "particles/s");
    for (int k = 0; k < 3; ++k) {
        for (int sc = 0; sc < SETS; ++sc)
            for (int t = 0; t < 2; ++t) {
                const int id = (k * SETS + sc) * 2 + t;
                if (!used[id]) continue;
                const result* x = &best[id];
                printf("%-11s %-7s %7d %9zu %10.2f %10.2f %9.2f %9.0f%% %12.3g\n", names[k],
                       ak_fluid_kernels_name(sets[sc]), t + 1, x->count, x->wall_ms, x->cpu_ms,
                       x->nb_ms, 100.0 * x->nb_ms / x->wall_ms,
                       (double)x->count / (x->wall_ms * 1e-3));
            }
        const int scalar1 = (k * SETS + SETS - 1) * 2;
        for (int sc = 0; sc < SETS; ++sc) {
            const int one = (k * SETS + sc) * 2;
            if (!used[one] || !used[one + 1]) continue;
            printf("%-11s %-7s 2 vs 1 thread: wall %.2fx, cpu %.2fx; cpu per particle-step %.0f ns "
                   "(1 thread)",
                   names[k], ak_fluid_kernels_name(sets[sc]),
                   best[one].wall_ms / best[one + 1].wall_ms,
                   best[one].cpu_ms / best[one + 1].cpu_ms,
                   best[one].cpu_ms * 1e6 / (double)best[one].count);
            if (sc != SETS - 1 && used[scalar1])
                printf("; SIMD/scalar cpu time: %.2f (1 thread), %.2f (2 threads)",
                       best[one].cpu_ms / best[scalar1].cpu_ms,
                       best[one + 1].cpu_ms / best[scalar1 + 1].cpu_ms);
            printf("\n");
        }
    }
    return 0;
}
