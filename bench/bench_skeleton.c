/* bench_skeleton: forward kinematics, mesh queries and built-in model creation.
 *
 * FK over a 64-joint random skeleton: ak_skeleton_local_to_model (matrix chain) against a
 * TRS-composition chain (ak_transform_mul, then one matrix per joint, exact only for uniform
 * scale) and against the batch entry point over 256 characters. Then the mesh queries on the
 * built-in humanoid and the time to build each built-in model. Passes alternate; each side
 * reports the best of N, timed with the thread's CPU clock so machine load skews neither. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_clock.h"

#include <animkit/builtin.h>

enum { J = 64, CHARS = 256, REPS = 15 };

static volatile float sink;

int main(void) {
    /* Random skeleton and poses (fixed seed). */
    ak_rng rng = ak_rng_make(2024);
    static char names[J][16];
    ak_joint_desc js[J];
    memset(js, 0, sizeof js);
    for (int i = 0; i < J; ++i) {
        snprintf(names[i], sizeof names[i], "j%d", i);
        js[i].name = names[i];
        js[i].parent = i == 0 ? -1 : (int)(ak_rng_u32(&rng) % (uint32_t)i);
        js[i].rest = ak_transform_identity();
        js[i].rest.translation = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), 0.3f);
    }
    ak_skeleton* sk = NULL;
    ak_skeleton_desc sd = {.joints = js, .joint_count = J};
    if (ak_skeleton_create(&sd, NULL, &sk, NULL) != AK_OK) return 1;
    ak_transform* poses = (ak_transform*)malloc(CHARS * J * sizeof(ak_transform));
    ak_mat4* model = (ak_mat4*)malloc(CHARS * J * sizeof(ak_mat4));
    ak_transform* tmp = (ak_transform*)malloc(J * sizeof(ak_transform));
    for (int i = 0; i < CHARS * J; ++i) {
        ak_quat q = ak_quat_normalize(ak_quat_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                                                   ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1)));
        poses[i] = ak_transform_make(ak_vec3_make(0.1f, 0.5f, 0.0f), q, ak_vec3_one());
    }
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    double best_mat = 1e9, best_trs = 1e9, best_batch = 1e9;
    for (int rep = 0; rep < REPS; ++rep) {
        double t0 = bench_cpu_s();
        for (int c = 0; c < CHARS; ++c)
            ak_skeleton_local_to_model(sk, (ak_transform_cspan){poses + c * J, J}, (ak_mat4_span){model + c * J, J});
        double t1 = bench_cpu_s();
        for (int c = 0; c < CHARS; ++c) {
            const ak_transform* p = poses + c * J;
            for (int i = 0; i < J; ++i) {
                tmp[i] = parents.ptr[i] < 0 ? p[i] : ak_transform_mul(tmp[parents.ptr[i]], p[i]);
                model[c * J + i] = ak_transform_to_mat4(tmp[i]);
            }
        }
        double t2 = bench_cpu_s();
        ak_skeleton_local_to_model_batch(sk, CHARS, (ak_transform_cspan){poses, CHARS * J},
                                         (ak_mat4_span){model, CHARS * J});
        double t3 = bench_cpu_s();
        sink = model[CHARS * J - 1].m[12];
        if (t1 - t0 < best_mat) best_mat = t1 - t0;
        if (t2 - t1 < best_trs) best_trs = t2 - t1;
        if (t3 - t2 < best_batch) best_batch = t3 - t2;
    }
    /* Each FK kernel this CPU has (ak_skeleton_set_simd_limit), interleaved rep by rep. */
    double best_k[AK_FK_SIMD_COUNT];
    char kname[AK_FK_SIMD_COUNT][16];
    for (int k = 0; k < AK_FK_SIMD_COUNT; ++k) best_k[k] = 1e9;
    for (int rep = 0; rep < REPS; ++rep)
        for (int k = AK_FK_SIMD_SCALAR; k < AK_FK_SIMD_COUNT; ++k) {
            ak_skeleton_set_simd_limit(sk, (ak_fk_simd)k);
            snprintf(kname[k], sizeof kname[k], "%s", ak_skeleton_simd_name(sk));
            double t0 = bench_cpu_s();
            for (int c = 0; c < CHARS; ++c)
                ak_skeleton_local_to_model(sk, (ak_transform_cspan){poses + c * J, J}, (ak_mat4_span){model + c * J, J});
            double t1 = bench_cpu_s();
            if (t1 - t0 < best_k[k]) best_k[k] = t1 - t0;
        }
    ak_skeleton_set_simd_limit(sk, AK_FK_SIMD_DEFAULT);
    const double jn = (double)CHARS * J;
    printf("FK, %d joints x %d characters, best of %d (thread CPU time)\n", J, CHARS, REPS);
    for (int k = AK_FK_SIMD_SCALAR; k < AK_FK_SIMD_COUNT; ++k)
        printf("  kernel limit %d: %-8s %8.2f Mjoints/s   time vs scalar %.2f\n", k, kname[k], jn / best_k[k] * 1e-6,
               best_k[k] / best_k[AK_FK_SIMD_SCALAR]);
    printf("  local_to_model (matrix chain)   %8.2f Mjoints/s\n", jn / best_mat * 1e-6);
    printf("  TRS compose + to_mat4           %8.2f Mjoints/s   matrix/TRS time ratio %.2f\n",
           jn / best_trs * 1e-6, best_mat / best_trs);
    printf("  local_to_model_batch            %8.2f Mjoints/s   batch/single time ratio %.2f\n",
           jn / best_batch * 1e-6, best_batch / best_mat);

    /* Built-in models and mesh queries. */
    double best_h = 1e9, best_c = 1e9;
    ak_scene* hs = NULL;
    for (int rep = 0; rep < 3; ++rep) {
        ak_scene* s = NULL;
        double t0 = bench_cpu_s();
        ak_builtin_create("humanoid", NULL, NULL, &s);
        double t1 = bench_cpu_s();
        ak_scene* c = NULL;
        ak_builtin_create("cylinder", NULL, NULL, &c);
        double t2 = bench_cpu_s();
        ak_scene_destroy(c);
        if (t1 - t0 < best_h) best_h = t1 - t0;
        if (t2 - t1 < best_c) best_c = t2 - t1;
        if (hs) ak_scene_destroy(hs);
        hs = s;
    }
    if (!hs) return 1;
    const ak_mesh* m = hs->meshes[0].mesh;
    printf("builtin:humanoid create %.1f ms (%zu triangles); builtin:cylinder create %.2f ms\n", best_h * 1e3,
           m->triangle_count, best_c * 1e3);
    ak_vec3* nrm = (ak_vec3*)malloc(m->vertex_count * sizeof(ak_vec3));
    double best_closed = 1e9, best_norm = 1e9, best_vol = 1e9;
    for (int rep = 0; rep < REPS; ++rep) {
        double t0 = bench_cpu_s();
        bool closed = ak_mesh_is_closed_oriented(m);
        double t1 = bench_cpu_s();
        ak_normals_compute((ak_vec3_cspan){m->positions, m->vertex_count},
                           (ak_u32_cspan){m->indices, 3 * m->triangle_count}, (ak_vec3_span){nrm, m->vertex_count});
        double t2 = bench_cpu_s();
        double v = ak_volume_compute((ak_vec3_cspan){m->positions, m->vertex_count},
                                     (ak_u32_cspan){m->indices, 3 * m->triangle_count});
        double t3 = bench_cpu_s();
        sink = (float)v + (closed ? 1.0f : 0.0f) + nrm[0].x;
        if (t1 - t0 < best_closed) best_closed = t1 - t0;
        if (t2 - t1 < best_norm) best_norm = t2 - t1;
        if (t3 - t2 < best_vol) best_vol = t3 - t2;
    }
    const double tn = (double)m->triangle_count;
    printf("mesh queries on the humanoid, best of %d\n", REPS);
    printf("  is_closed_oriented %8.2f Mtriangles/s\n", tn / best_closed * 1e-6);
    printf("  normals_compute    %8.2f Mtriangles/s   closed-check/normals time ratio %.1f\n", tn / best_norm * 1e-6,
           best_closed / best_norm);
    printf("  volume_compute     %8.2f Mtriangles/s\n", tn / best_vol * 1e-6);
    free(nrm);
    ak_scene_destroy(hs);
    free(poses);
    free(model);
    free(tmp);
    ak_skeleton_destroy(sk);
    return 0;
}
