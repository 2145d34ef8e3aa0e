/* IK benchmark: success rate, iterations and time per solve of CCD, FABRIK and DLS (and
 * two-bone on 3 joints) over 10,000 seeded random reachable targets, for planar chains (z
 * hinges) and 3D chains (free joints) of 3, 10 and 30 joints. Success: effector within
 * 1e-4 x chain length in at most 50 iterations. Targets are effector positions of random poses
 * (each joint turned up to 1.2 rad), so every one is reachable; every solve starts from the same
 * slightly bent pose. Also: ns per solve of the analytic two-bone job (model space) against
 * the chain job running the same solver, measured side by side.
 *
 *     build/bench/bench_ik [target_count]      (default 10000) */
#include <animkit/ik.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_clock.h"

#define MAXJ 30

static ak_skeleton* make_chain(size_t n, bool planar, ak_rng* rng) {
    ak_joint_desc j[MAXJ];
    char names[MAXJ][24];
    memset(j, 0, sizeof j);
    for (size_t i = 0; i < n; ++i) {
        snprintf(names[i], sizeof names[i], "j%zu", i);
        j[i].name = names[i];
        j[i].parent = (int)i - 1;
        j[i].rest = ak_transform_identity();
        if (i > 0) j[i].rest.translation = ak_vec3_make(ak_rng_range(rng, 0.5f, 1.5f), 0.0f, 0.0f);
        if (planar) {
            j[i].type = AK_JOINT_HINGE;
            j[i].limits.axis = ak_vec3_make(0, 0, 1);
        }
    }
    ak_skeleton_desc d = {.joints = j, .joint_count = n};
    ak_skeleton* sk = NULL;
    if (ak_skeleton_create(&d, NULL, &sk, NULL) != AK_OK) return NULL;
    return sk;
}

/* Random pose: each joint turned up to 1.2 rad (about z when planar). */
static void random_pose(const ak_skeleton* sk, bool planar, ak_rng* rng, ak_transform* pose) {
    size_t n = ak_skeleton_joint_count(sk);
    memcpy(pose, ak_skeleton_rest_pose(sk).ptr, n * sizeof *pose);
    for (size_t i = 0; i < n; ++i) {
        ak_vec3 axis = planar ? ak_vec3_make(0, 0, 1)
                              : ak_vec3_make(ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1));
        pose[i].rotation = ak_quat_from_axis_angle(axis, ak_rng_range(rng, -1.2f, 1.2f));
    }
}

/* The common start: every joint bent 0.2 rad about z (and 0.1 about y in 3D). */
static void start_pose(const ak_skeleton* sk, bool planar, ak_transform* pose) {
    size_t n = ak_skeleton_joint_count(sk);
    memcpy(pose, ak_skeleton_rest_pose(sk).ptr, n * sizeof *pose);
    const float bend = getenv("AK_BENCH_IK_BEND") ? (float)atof(getenv("AK_BENCH_IK_BEND")) : 0.2f;
    for (size_t i = 0; i < n; ++i) {
        pose[i].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), bend);
        if (!planar)
            pose[i].rotation = ak_quat_mul(pose[i].rotation, ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.1f));
    }
}

typedef struct result {
    double success, it_median, it_p99, us_median;
} result;

static unsigned char scratch[1 << 20];

static size_t bench_iterations(void) {
    const char* e = getenv("AK_BENCH_IK_ITERATIONS");
    return e ? (size_t)strtoul(e, NULL, 10) : 50;
}

static result run_solver(const ak_skeleton* sk, bool planar, const ak_vec3* targets, size_t count, ak_ik_solver solver,
                         double* it_buf, double* us_buf) {
    const size_t n = ak_skeleton_joint_count(sk);
    int16_t chain[MAXJ];
    for (size_t i = 0; i < n; ++i) chain[i] = (int16_t)i;
    ak_transform start[MAXJ], pose[MAXJ];
    start_pose(sk, planar, start);
    const float len = ak_ik_chain_length(sk, (ak_transform_cspan){start, n}, (ak_i16_cspan){chain, n});
    size_t ok = 0;
    for (size_t t = 0; t < count; ++t) {
        memcpy(pose, start, n * sizeof *pose);
        bool reached = false;
        size_t iterations = 0;
        ak_ik_chain_job job = {.skeleton = sk,
                               .pose = {pose, n},
                               .chain = {chain, n},
                               .target = targets[t],
                               .solver = solver,
                               .max_iterations = bench_iterations(),
                               .tolerance = 1e-4f * len,
                               .scratch = AK_SPAN(scratch),
                               .out_reached = &reached,
                               .out_iterations = &iterations};
        double t0 = bench_wall_s();
        ak_result r = ak_ik_chain_run(&job);
        double t1 = bench_wall_s();
        if (r != AK_OK) {
            fprintf(stderr, "solve failed: %s\n", ak_result_string(r));
            exit(1);
        }
        ok += reached;
        it_buf[t] = (double)iterations;
        us_buf[t] = (t1 - t0) * 1e6;
    }
    result res;
    res.success = 100.0 * (double)ok / (double)count;
    res.it_median = bench_percentile(it_buf, count, 0.5);
    res.it_p99 = bench_percentile(it_buf, count, 0.99);
    res.us_median = bench_percentile(us_buf, count, 0.5);
    return res;
}

/* The benchmark's two-bone job: the 3-joint chain in its start pose, pole +z. */
static ak_ik_two_bone_job limb_job(const ak_skeleton* sk, ak_quat* qs, ak_quat* qm) {
    ak_transform pose[3];
    start_pose(sk, false, pose);
    ak_mat4 model[3];
    ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, 3}, (ak_mat4_span){model, 3});
    ak_ik_two_bone_job job = {.start = model[0],
                              .mid = model[1],
                              .end = model[2],
                              .pole = ak_vec3_make(0, 0, 1),
                              .out_start_rot = qs,
                              .out_mid_rot = qm};
    return job;
}

/* ns per solve of the model-space two-bone job: the median over batches of 64 solves of the
 * wall time (robust to preemption on a loaded machine), and thread CPU time over 10 passes. */
static double two_bone_job_ns(const ak_skeleton* sk, const ak_vec3* targets, size_t count, double* sink,
                              double* out_cpu_ns) {
    ak_quat qs, qm;
    ak_ik_two_bone_job job = limb_job(sk, &qs, &qm);
    const size_t batch = 64, batches = 10 * count / batch;
    double* per = malloc(batches * sizeof *per);
    if (!per) return 0.0;
    double acc = 0.0;
    const double c0 = bench_cpu_s();
    for (size_t k = 0; k < batches; ++k) {
        const double t0 = bench_wall_s();
        for (size_t i = 0; i < batch; ++i) {
            job.target = targets[(k * batch + i) % count];
            ak_ik_two_bone_run(&job);
            acc += (double)qs.w + (double)qm.w;
        }
        per[k] = (bench_wall_s() - t0) * 1e9 / (double)batch;
    }
    *out_cpu_ns = (bench_cpu_s() - c0) * 1e9 / (double)(batches * batch);
    *sink += acc;
    const double med = bench_percentile(per, batches, 0.5);
    free(per);
    return med;
}

/* ns per solve of ak_ik_two_bone_run_many over batches of 64 jobs (the same limb and
 * targets as two_bone_job_ns): the median over batches of the wall time per solve, and the
 * single job timed the same way in the same loop (batch of 64 run one by one), for the ratio. */
static double two_bone_many_ns(const ak_skeleton* sk, const ak_vec3* targets, size_t count, double* sink,
                               double* out_single_ns) {
    enum { B = 64 };
    static ak_ik_two_bone_job jobs[B];
    static ak_quat qs[B], qm[B];
    for (size_t i = 0; i < B; ++i) jobs[i] = limb_job(sk, &qs[i], &qm[i]);
    const size_t batches = 10 * count / B;
    double* many = malloc(batches * sizeof *many);
    double* single = malloc(batches * sizeof *single);
    if (!many || !single) {
        free(many), free(single);
        return 0.0;
    }
    double acc = 0.0;
    for (size_t k = 0; k < batches; ++k) {
        for (size_t i = 0; i < B; ++i) jobs[i].target = targets[(k * B + i) % count];
        double t0 = bench_wall_s();
        ak_ik_two_bone_run_many(jobs, B, NULL);
        double t1 = bench_wall_s();
        for (size_t i = 0; i < B; ++i) ak_ik_two_bone_run(&jobs[i]);
        double t2 = bench_wall_s();
        many[k] = (t1 - t0) * 1e9 / B;
        single[k] = (t2 - t1) * 1e9 / B;
        acc += (double)qs[k % B].w + (double)qm[k % B].w;
    }
    *sink += acc;
    const double med = bench_percentile(many, batches, 0.5);
    *out_single_ns = bench_percentile(single, batches, 0.5);
    free(many), free(single);
    return med;
}

int main(int argc, char** argv) {
    size_t count = argc > 1 ? (size_t)strtoul(argv[1], NULL, 10) : 10000;
    if (count < 10) count = 10;
    ak_vec3* targets = malloc(count * sizeof *targets);
    double* it_buf = malloc(count * sizeof *it_buf);
    double* us_buf = malloc(count * sizeof *us_buf);
    if (!targets || !it_buf || !us_buf) return 1;
    const size_t sizes[3] = {3, 10, 30};
    const ak_ik_solver solvers[4] = {AK_IK_SOLVER_CCD, AK_IK_SOLVER_FABRIK, AK_IK_SOLVER_DLS, AK_IK_SOLVER_TWO_BONE};
    double sink = 0.0;
    printf("animkit bench_ik: %zu random reachable targets per chain, success = error <= 1e-4 x chain length "
           "within 50 iterations\n\n",
           count);
    printf("%-6s %6s %-8s %9s %8s %8s %10s %12s\n", "chain", "joints", "solver", "success%", "it.med", "it.p99",
           "us.median", "vs FABRIK");
    for (int planar = 1; planar >= 0; --planar) {
        for (int si = 0; si < 3; ++si) {
            const size_t n = sizes[si];
            ak_rng rng = ak_rng_make(1000 + (uint64_t)(n * 2 + (size_t)planar));
            ak_skeleton* sk = make_chain(n, planar, &rng);
            if (!sk) return 1;
            ak_transform pose[MAXJ];
            int16_t chain[MAXJ];
            for (size_t i = 0; i < n; ++i) chain[i] = (int16_t)i;
            for (size_t t = 0; t < count; ++t) {
                ak_vec3 pos[MAXJ];
                random_pose(sk, planar, &rng, pose);
                ak_ik_chain_positions(sk, (ak_transform_cspan){pose, n}, (ak_i16_cspan){chain, n},
                                      (ak_vec3_span){pos, n});
                targets[t] = pos[n - 1];
            }
            result res[4];
            int solver_count = n == 3 ? 4 : 3;
            for (int k = 0; k < solver_count; ++k)
                res[k] = run_solver(sk, planar, targets, count, solvers[k], it_buf, us_buf);
            for (int k = 0; k < solver_count; ++k)
                printf("%-6s %6zu %-8s %9.2f %8.0f %8.0f %10.3f %11.2fx\n", planar ? "planar" : "3d", n,
                       ak_ik_solver_name(solvers[k]), res[k].success, res[k].it_median, res[k].it_p99,
                       res[k].us_median, res[k].us_median / res[1].us_median);
            if (n == 3 && !planar) {
                double cpu_ns = 0.0;
                double ns = two_bone_job_ns(sk, targets, count, &sink, &cpu_ns);
                printf("\ntwo-bone job (model space, pole, no limits): %.1f ns/solve (median of 64-solve batches, "
                       "wall), %.1f ns/solve (thread CPU time), %.1f M solves/s; chain job TWO_BONE (validate, FK, "
                       "limits, error): %.3f us/solve = %.1fx the job\n\n",
                       ns, cpu_ns, 1e3 / ns, res[3].us_median, res[3].us_median * 1e3 / ns);
                double single_ns = 0.0;
                double many_ns = two_bone_many_ns(sk, targets, count, &sink, &single_ns);
                printf("two-bone ak_ik_two_bone_run_many (batches of 64 jobs, same limb and targets): %.1f ns/solve, "
                       "%.1f M solves/s; the single job in the same loop %.1f ns/solve: x%.2f\n\n",
                       many_ns, 1e3 / many_ns, single_ns, single_ns / many_ns);
            }
            ak_skeleton_destroy(sk);
        }
    }
    if (sink == 12345.678) printf("(sink)\n");
    free(targets);
    free(it_buf);
    free(us_buf);
    return 0;
}
