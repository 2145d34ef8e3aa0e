/* Cloth step timings: a W x W cloth draped on a sphere, 1/60 s frames.
 *   - XPBD, 10 substeps per frame, 64 x 64 (dihedral, isometric, distance-constraint or no
 *     bending) and 256 x 256, on 1 and 2 threads: ms per frame and ns per particle-substep;
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
                     ak_cloth_bending bending) {
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
                                 .thread_count = threads, .positions = {r->x, r->n}, .velocities = {r->v, r->n}};
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
    bool ok = run_init(&r, AK_CLOTH_SPRINGS, w, substeps, 1, AK_CLOTH_BEND_DEFAULT);
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
    printf("cloth draped on a sphere, 1/60 s frames, median of %d frames\n", frames);
    printf("%-9s %-8s %9s %8s %10s %10s %10s %16s\n", "cloth", "solver", "substeps", "threads", "median ms", "min ms",
           "cpu ms", "min ns/part-sub");
    double xpbd64 = 0.0;
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
        for (uint32_t th = 1; th <= 2; ++th) {
            run r;
            if (!run_init(&r, AK_CLOTH_XPBD, cases[s].size, 10, th, cases[s].bending)) return 1;
            const timing tm = time_frames(&r, fr);
            printf("%3ux%-5u %-8s %9d %8u %10.3f %10.3f %10.3f %16.2f\n", cases[s].size, cases[s].size, cases[s].name, 10,
                   th, tm.median, tm.min, tm.cpu, 1e6 * tm.min / (10.0 * (double)r.n));
            if (th == 1) one = tm.min;
            else printf("          2-thread speed-up (min) %.2fx\n", one / tm.min);
            if (s == 0 && th == 1) xpbd64 = tm.min;
            run_free(&r);
        }
    }
    printf("(XPBD: dihedral bending; -iso: isometric bending; -bs: bending distance constraints; -nb: none)\n");
    /* mass-spring at the step it needs for the same stiffness */
    uint32_t sub = 10;
    while (sub <= 5120 && !springs_stable(64, sub)) sub *= 2;
    if (sub > 5120) {
        printf("mass-spring: unstable up to 5120 substeps\n");
        return 0;
    }
    run r;
    if (!run_init(&r, AK_CLOTH_SPRINGS, 64, sub, 1, AK_CLOTH_BEND_DEFAULT)) return 1;
    const timing tm = time_frames(&r, frames / 4 > 5 ? frames / 4 : 5);
    const double ms = tm.min;
    printf("%3ux%-5u %-8s %9u %8u %10.3f %10.3f %10.3f %16.2f\n", 64, 64, "springs", sub, 1, tm.median, tm.min, tm.cpu,
           1e6 * ms / ((double)sub * (double)r.n));
    printf("mass-spring needs %u substeps per frame (h = %.3g ms) where XPBD uses 10 (h = %.3g ms): %.1fx the time "
           "per frame (min)\n",
           sub, 1e3 / 60.0 / sub, 1e3 / 600.0, ms / xpbd64);
    run_free(&r);
    return 0;
}
