/* Cloth step timings: a W x W cloth draped on a sphere, 1/60 s frames.
 *   - XPBD, 10 substeps per frame, 64 x 64 (dihedral, isometric, distance-constraint or no
 *     bending) and 256 x 256, on 1 and 2 threads (2: thread_count 2, which the step's rule may
 *     run on one thread; 2x: exact_thread_count): ms per frame and ns per particle-substep;
 *   - the constraint solves' SIMD paths side by side (scalar, AVX2, AVX-512 where the CPU has
 *     them), 64 x 64, one thread, interleaved in rounds: CPU ms per frame and the speed-up;
 *   - the mass-spring solver with the same spring constants (XPBD compliance = 1 / k): the
 *     smallest power-of-two substep count that stays finite and within 50% stretch for 2 s of
 *     the same scene, its ms per frame, and the time ratio to XPBD.
 * usage: bench_cloth [frames] (default 120) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/cloth.h>

#include "bench_clock.h"

typedef struct run {
    ak_cloth* cloth;
    size_t n;
    ak_vec3 *x, *v;
    ak_cloth_step_job job;
    ak_cloth_sphere sphere;
} run;

static bool run_init(run* r, ak_cloth_solver solver, uint32_t w, uint32_t substeps, uint32_t threads,
                     ak_cloth_bending bending, bool exact, ak_cloth_simd simd) {
    memset(r, 0, sizeof *r);
    ak_cloth_desc d = {.solver = solver, .grid_width = w, .grid_height = w, .spacing = 1.0f / (float)(w - 1),
                       .grid_origin = {-0.5f, 1.0f, 0.5f}, .bending = bending};
    if (ak_cloth_create(&d, NULL, &r->cloth) != AK_OK) return false;
    r->n = ak_cloth_vertex_count(r->cloth);
    r->x = malloc(r->n * sizeof(ak_vec3));
    r->v = calloc(r->n, sizeof(ak_vec3));
    ak_cloth_rest_positions(r->cloth, (ak_vec3_span){r->x, r->n});
    r->sphere = (ak_cloth_sphere){{0, 0.5f, 0}, 0.3f};
    r->job = (ak_cloth_step_job){.cloth = r->cloth, .dt = 1.0f / 60.0f, .substeps = substeps, .gravity = {0, -9.81f, 0},
                                 .spheres = &r->sphere, .sphere_count = 1, .friction = 0.3f, .damping = 0.5f,
                                 .thread_count = threads, .exact_thread_count = exact, .simd_limit = simd,
                                 .positions = {r->x, r->n}, .velocities = {r->v, r->n}};
    size_t size = ak_cloth_step_scratch_size(&r->job);
    r->job.scratch = (ak_u8_span){malloc(size), size};
    return r->x && r->v && r->job.scratch.ptr;
}

static void run_free(run* r) {
    free(r->job.scratch.ptr);
    free(r->x);
    free(r->v);
    ak_cloth_destroy(r->cloth);
}

/* Per-frame times over `frames` frames after 10 warm-up frames: median and minimum wall ms, and
 * process CPU ms per frame (all threads); median -1 on a blow-up. On a machine other jobs load,
 * the minimum and the CPU time are the better estimates of an idle machine's wall time. */
typedef struct timing {
    double median, min, cpu;
} timing;

static timing time_frames(run* r, int frames) {
    timing out = {-1.0, -1.0, -1.0};
    for (int f = 0; f < 10; ++f)
        if (ak_cloth_step_run(&r->job) != AK_OK) return out;
    double* t = malloc((size_t)frames * sizeof(double));
    const double c0 = bench_proc_s();
    for (int f = 0; f < frames; ++f) {
        const double t0 = bench_wall_s();
        if (ak_cloth_step_run(&r->job) != AK_OK) {
            free(t);
            return out;
        }
        t[f] = 1e3 * (bench_wall_s() - t0);
    }
    out.cpu = 1e3 * (bench_proc_s() - c0) / frames;
    out.median = bench_percentile(t, (size_t)frames, 0.5);
    out.min = t[0]; /* sorted by bench_percentile */
    free(t);
    return out;
}

/* Does the spring solver survive 2 s of the scene with this many substeps? */
static bool springs_stable(uint32_t w, uint32_t substeps) {
    run r;
    bool ok = run_init(&r, AK_CLOTH_SPRINGS, w, substeps, 1, AK_CLOTH_BEND_DEFAULT, false, AK_CLOTH_SIMD_DEFAULT);
    for (int f = 0; ok && f < 120; ++f) {
        ok = ak_cloth_step_run(&r.job) == AK_OK;
        if (ok) ok = ak_cloth_max_stretch(r.cloth, (ak_vec3_cspan){r.x, r.n}) < 0.5f;
    }
    run_free(&r);
    return ok;
}

int main(int argc, char** argv) {
    const int frames = argc > 1 ? atoi(argv[1]) : 120;
    if (frames < 1) return 2;
    printf("cloth draped on a sphere, 1/60 s frames, median of %d frames; widest constraint solve: %s\n", frames,
           ak_cloth_simd_name());
    printf("%-9s %-8s %9s %8s %10s %10s %10s %16s\n", "cloth", "solver", "substeps", "threads", "median ms", "min ms",
           "cpu ms", "cpu ns/part-sub");
    double xpbd64 = 0.0, xpbd64_cpu = 0.0;
    const struct {
        uint32_t size;
        ak_cloth_bending bending;
        const char* name;
    } cases[5] = {{64, AK_CLOTH_BEND_DIHEDRAL, "XPBD"},
                  {64, AK_CLOTH_BEND_ISOMETRIC, "XPBD-iso"},
                  {64, AK_CLOTH_BEND_SPRINGS, "XPBD-bs"},
                  {64, AK_CLOTH_BEND_NONE, "XPBD-nb"},
                  {256, AK_CLOTH_BEND_DIHEDRAL, "XPBD"}};
    for (int s = 0; s < 5; ++s) {
        const int fr = cases[s].size == 256 ? (frames / 8 > 5 ? frames / 8 : 5) : frames;
        double one = 0.0;
        for (int mode = 0; mode < 3; ++mode) { /* 1 thread, 2 by the rule, exactly 2 */
            const uint32_t th = mode == 0 ? 1 : 2;
            run r;
            if (!run_init(&r, AK_CLOTH_XPBD, cases[s].size, 10, th, cases[s].bending, mode == 2, AK_CLOTH_SIMD_DEFAULT))
                return 1;
            const timing tm = time_frames(&r, fr);
            printf("%3ux%-5u %-8s %9d %8s %10.3f %10.3f %10.3f %16.2f\n", cases[s].size, cases[s].size, cases[s].name, 10,
                   mode == 0 ? "1" : mode == 1 ? "2" : "2x", tm.median, tm.min, tm.cpu,
                   1e6 * tm.cpu / (10.0 * (double)r.n));
            if (mode == 0) one = tm.min;
            else printf("          %s speed-up (min wall) %.2fx\n", mode == 1 ? "2-thread" : "exactly-2-thread", one / tm.min);
            if (s == 0 && mode == 0) xpbd64 = tm.min, xpbd64_cpu = tm.cpu;
            run_free(&r);
        }
    }
    printf("(XPBD: dihedral bending; -iso: isometric bending; -bs: bending distance constraints; -nb: none;\n"
           " threads 2: thread_count 2 under the step's rule, 2x: exact_thread_count)\n");
    /* SIMD paths side by side: rounds of `per` frames of each path in turn, CPU time */
    {
        const ak_cloth_simd paths[3] = {AK_CLOTH_SIMD_SCALAR, AK_CLOTH_SIMD_AVX2, AK_CLOTH_SIMD_AVX512};
        const char* names[3] = {"scalar", "avx2", "avx512"};
        const char* widest = ak_cloth_simd_name();
        const int npaths = strcmp(widest, "avx512") == 0 ? 3 : strcmp(widest, "avx2") == 0 ? 2 : 1;
        const int rounds = 5, per = frames / 5 > 4 ? frames / 5 : 4;
        printf("\nconstraint solve paths, 64x64, 1 thread, %d rounds of %d frames each, interleaved: CPU ms per frame "
               "(best round / all rounds)\n",
               rounds, per);
        for (int s = 0; s < 4; ++s) {
            run rs[3];
            double best[3], total[3];
            for (int p = 0; p < npaths; ++p) {
                if (!run_init(&rs[p], AK_CLOTH_XPBD, 64, 10, 1, cases[s].bending, false, paths[p])) return 1;
                for (int f = 0; f < 10; ++f) ak_cloth_step_run(&rs[p].job);
                best[p] = 1e30, total[p] = 0.0;
            }
            for (int round = 0; round < rounds; ++round)
                for (int p = 0; p < npaths; ++p) {
                    const double c0 = bench_proc_s();
                    for (int f = 0; f < per; ++f) ak_cloth_step_run(&rs[p].job);
                    const double ms = 1e3 * (bench_proc_s() - c0) / per;
                    best[p] = ms < best[p] ? ms : best[p];
                    total[p] += ms / rounds;
                }
            printf("  %-9s", cases[s].name);
            for (int p = 0; p < npaths; ++p)
                printf("  %s %6.3f / %6.3f%s", names[p], best[p], total[p], p ? "" : "");
            for (int p = 1; p < npaths; ++p) printf("  scalar/%s %.2fx", names[p], total[0] / total[p]);
            printf("\n");
            for (int p = 0; p < npaths; ++p) run_free(&rs[p]);
        }
        if (npaths < 3) printf("  (SKIP: %s)\n", npaths == 1 ? "no AVX2 or AVX-512 on this CPU/build" : "no AVX-512 on this CPU");
    }
    /* mass-spring at the step it needs for the same stiffness */
    if (bench_quick()) {
        printf("mass-spring: skipped (AK_BENCH_QUICK)\n");
        return 0;
    }
    uint32_t sub = 10;
    while (sub <= 5120 && !springs_stable(64, sub)) sub *= 2;
    if (sub > 5120) {
        printf("mass-spring: unstable up to 5120 substeps\n");
        return 0;
    }
    run r;
    if (!run_init(&r, AK_CLOTH_SPRINGS, 64, sub, 1, AK_CLOTH_BEND_DEFAULT, false, AK_CLOTH_SIMD_DEFAULT)) return 1;
    const timing tm = time_frames(&r, frames / 4 > 5 ? frames / 4 : 5);
    const double ms = tm.min;
    printf("%3ux%-5u %-8s %9u %8u %10.3f %10.3f %10.3f %16.2f\n", 64, 64, "springs", sub, 1, tm.median, tm.min, tm.cpu,
           1e6 * ms / ((double)sub * (double)r.n));
    printf("mass-spring needs %u substeps per frame (h = %.3g ms) where XPBD uses 10 (h = %.3g ms): %.1fx the CPU time "
           "per frame (%.1fx the min wall time)\n",
           sub, 1e3 / 60.0 / sub, 1e3 / 600.0, tm.cpu / xpbd64_cpu, ms / xpbd64);
    run_free(&r);
    return 0;
}
