/* Implicit skinning (ak_skin_implicit_*) beside DQS in the same run: ms per frame on CesiumMan
 * (when the asset is present: ANIMKIT_ASSETS or ../shared/assets) and on builtin:cylinder
 * tessellated to about 50k vertices, 1 and 2 threads (wall time), plus the CPU time of one
 * thread (on a loaded machine the fairer ratio) and the same frame with the HRBFs evaluated
 * directly instead of from the per-bone grids, and the frame with the scalar projections
 * (simd_limit AK_SKIN_SIMD_SCALAR: one vertex at a time instead of the AVX-512 / AVX2 lanes); the
 * precompute times. The ratio implicit / DQS
 * per frame is machine-independent enough to compare (target <= 5x).
 *     build/bench/bench_implicit */
#include <stdio.h>
#include <string.h>

#include <animkit/animkit.h>

#include "bench_clock.h"

typedef struct model {
    const char* name;
    ak_scene* scene;
} model;

/* Median ms of rounds runs of fn. */
typedef struct frame_ctx {
    const ak_mesh* mesh;
    ak_skin_implicit* imp;
    const ak_mat4* pal;
    size_t joint_count;
    ak_vec3* out;
    unsigned char* scratch;
    size_t scratch_size;
    uint32_t threads;
    ak_skin_simd simd; /* the projections' kernel (0: the fastest this CPU has) */
} frame_ctx;

static void run_dqs(const frame_ctx* c) {
    const ak_mesh* m = c->mesh;
    ak_skin_job job = {
        .method = AK_SKIN_DQS,
        .influence_count = m->influence_count,
        .palette = {c->pal, c->joint_count},
        .positions = {m->positions, m->vertex_count, 0},
        .joints = {m->joints, m->vertex_count, 0},
        .weights = {m->weights, m->vertex_count, 0},
        .skip_data_check = true,
        .thread_count = c->threads,
        .scratch = {c->scratch, c->scratch_size},
        .out_positions = {c->out, m->vertex_count, 0},
    };
    ak_skin_job_run(&job);
}

static void run_implicit(const frame_ctx* c) {
    ak_skin_implicit_job job = {
        .implicit = c->imp,
        .palette = {c->pal, c->joint_count},
        .thread_count = c->threads,
        .simd_limit = c->simd,
        .scratch = {c->scratch, c->scratch_size},
        .out_positions = {c->out, c->mesh->vertex_count},
    };
    ak_skin_implicit_run(&job);
}

static double median_ms_clock(void (*fn)(const frame_ctx*), const frame_ctx* c, int rounds, double (*clk)(void)) {
    double t[64];
    if (rounds > 64) rounds = 64;
    fn(c); /* warm */
    for (int r = 0; r < rounds; ++r) {
        double t0 = clk();
        fn(c);
        t[r] = 1e3 * (clk() - t0);
    }
    return bench_percentile(t, (size_t)rounds, 0.5);
}
static double median_ms(void (*fn)(const frame_ctx*), const frame_ctx* c, int rounds) {
    return median_ms_clock(fn, c, rounds, bench_wall_s);
}

static void bench_model(const char* name, ak_scene* s, int clip, float t) {
    const ak_scene_mesh* sm = &s->meshes[0];
    const ak_mesh* m = sm->mesh;
    size_t jc = s->skins[sm->skin].joint_count, nj = ak_scene_joint_count(s);
    ak_transform* local = malloc(nj * sizeof *local);
    ak_mat4* world = malloc(nj * sizeof *world);
    ak_mat4* pal = malloc(jc * sizeof *pal);
    ak_vec3* out = malloc(m->vertex_count * sizeof *out);
    ak_scene_rest_pose(s, (ak_transform_span){local, nj});
    if (clip >= 0 && (size_t)clip < s->clip_count)
        ak_clip_sample(s->clips[clip], t, NULL, (ak_transform_span){local, nj}, (ak_f32_span){0}, (ak_f32_span){0});
    ak_scene_world_matrices(s, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj});
    ak_scene_skin_palette(s, (size_t)sm->skin, (ak_mat4_cspan){world, nj}, (ak_mat4_span){pal, jc});
    ak_skin_implicit_desc d = {
        .positions = {m->positions, m->vertex_count},
        .indices = {m->indices, 3 * m->triangle_count},
        .joints = {m->joints, m->vertex_count * m->influence_count},
        .weights = {m->weights, m->vertex_count * m->influence_count},
        .influence_count = m->influence_count,
        .joint_count = jc,
    };
    ak_skin_implicit* imp = NULL;
    double t0 = bench_wall_s();
    ak_result r = ak_skin_implicit_create(&d, NULL, &imp);
    double pre = bench_wall_s() - t0;
    if (r != AK_OK) {
        printf("%s: precompute failed: %s\n", name, ak_result_string(r));
        return;
    }
    ak_skin_implicit_desc dd = d;
    dd.grid_resolution = UINT32_MAX; /* the reference: HRBFs evaluated directly */
    ak_skin_implicit* direct = NULL;
    t0 = bench_wall_s();
    r = ak_skin_implicit_create(&dd, NULL, &direct);
    double pre_direct = bench_wall_s() - t0;
    if (r != AK_OK) direct = NULL;
    size_t ss = ak_skin_implicit_scratch_size(imp, jc), ss2 = direct ? ak_skin_implicit_scratch_size(direct, jc) : 0;
    if (ss2 > ss) ss = ss2;
    unsigned char* scratch = malloc(ss);
    printf("%s: %zu vertices, %zu joints; precompute %.3f s with grids, %.3f s without (2 threads)\n", name,
           m->vertex_count, jc, pre, pre_direct);
    printf("  %-8s %12s %12s %10s\n", "threads", "DQS ms", "implicit ms", "ratio");
    int rounds = bench_quick() ? 3 : 15;
    for (uint32_t th = 1; th <= 2; ++th) {
        frame_ctx c = {m, imp, pal, jc, out, scratch, ss, th, AK_SKIN_SIMD_DEFAULT};
        double dq = median_ms(run_dqs, &c, rounds * 4), im = median_ms(run_implicit, &c, rounds);
        printf("  %-8u %12.4f %12.3f %9.1fx\n", th, dq, im, im / dq);
    }
    {
        frame_ctx c = {m, imp, pal, jc, out, scratch, ss, 1, AK_SKIN_SIMD_DEFAULT};
        double dq = median_ms_clock(run_dqs, &c, rounds * 4, bench_cpu_s);
        double im = median_ms_clock(run_implicit, &c, rounds, bench_cpu_s);
        printf("  1 thread, CPU time: DQS %.4f ms, implicit %.3f ms (%.1fx)", dq, im, im / dq);
        c.simd = AK_SKIN_SIMD_SCALAR;
        double sc = median_ms_clock(run_implicit, &c, rounds, bench_cpu_s);
        printf(", scalar projections %.3f ms (%.1fx)", sc, sc / dq);
        c.simd = AK_SKIN_SIMD_DEFAULT;
        if (direct) {
            c.imp = direct;
            double di = median_ms_clock(run_implicit, &c, bench_quick() ? 1 : 3, bench_cpu_s);
            printf(", without grids %.3f ms (%.1fx): grids %.1fx faster", di, di / dq, di / im);
        }
        printf("\n");
    }
    ak_skin_implicit_destroy(direct);
    free(scratch);
    ak_skin_implicit_destroy(imp);
    free(local), free(world), free(pal), free(out);
}

int main(void) {
    const char* roots[3] = {getenv("ANIMKIT_ASSETS"), AK_SOURCE_DIR "/../shared/assets", "../shared/assets"};
    ak_scene* s = NULL;
    char path[1024];
    for (int k = 0; k < 3 && !s; ++k) {
        if (!roots[k]) continue;
        snprintf(path, sizeof path, "%s/gltf/CesiumMan/glTF-Binary/CesiumMan.glb", roots[k]);
        if (ak_io_load(path, NULL, NULL, &s, NULL) != AK_OK) s = NULL;
    }
    if (s) {
        bench_model("CesiumMan (walk, t = 0.5 s)", s, 0, 0.5f);
        ak_scene_destroy(s);
    } else {
        printf("CesiumMan: SKIP (asset not found)\n");
    }
    ak_builtin_desc bd = {.rings = 390, .segments = 128}; /* 391 * 128 + caps: about 50k vertices */
    s = NULL;
    if (ak_builtin_create("builtin:cylinder", &bd, NULL, &s) == AK_OK) {
        bench_model("builtin:cylinder 50k (bend clip, t = 1: 120 degrees)", s, 0, 1.0f);
        ak_scene_destroy(s);
    }
    return 0;
}
