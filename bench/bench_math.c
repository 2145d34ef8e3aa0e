/* Math core throughput: quaternion products, vector rotations, normalisations, SLERPs and
 * 4x4 products per second: the compiled array path (SSE2 unless built with AK_NO_SIMD)
 * against plain loops over the inline functions (scalar, and as the build's flags compile them:
 * Release is -O3, which auto-vectorises some of them; the column is labelled with the flags),
 * side by side in one run, plus SLERP, polar and Euler rates. Fixed seed. */
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "bench_clock.h"

#include <animkit/math.h>

#include "simd.h" /* only for AK_SIMD_NAME */

enum { N = 4096, REPS = 15 };

static ak_quat qa[N], qb[N], qo[N];
static ak_vec3 va[N], vo[N];
static ak_mat4 ma[N], mb[N], mo[N];
static float ts[N];
static ak_mat3 m3[N];
static volatile float sink;

/* Seconds per element of one run: the kernel over N elements, `inner` times. */
static double time_once(void (*fn)(void), int inner) {
    double t0 = bench_cpu_s();
    for (int k = 0; k < inner; ++k) fn();
    return (bench_cpu_s() - t0) / ((double)inner * N);
}

/* Best of REPS runs of each of two kernels, alternating, so both see the same machine load. */
static void time_pair(void (*a)(void), void (*b)(void), int inner, double* ta, double* tb) {
    *ta = *tb = 1e30;
    for (int r = 0; r < REPS; ++r) {
        double x = time_once(a, inner), y = time_once(b, inner);
        if (x < *ta) *ta = x;
        if (y < *tb) *tb = y;
    }
}

/* Each plain loop is compiled twice: as the build compiles it (gcc 12 at -O2 and -O3
 * auto-vectorises some of these
 * loops) and, on gcc, with auto-vectorisation switched off: the true scalar reference. */
#if defined(__GNUC__) && !defined(__clang__)
#define AK_BENCH_NOVEC __attribute__((optimize("no-tree-vectorize", "no-tree-slp-vectorize")))
#else
#define AK_BENCH_NOVEC
#endif
#define LOOP_PAIR(name, body)                                \
    static void loop_##name(void) { body }                   \
    static AK_BENCH_NOVEC void novec_##name(void) { body }

LOOP_PAIR(qmul, for (int i = 0; i < N; ++i) qo[i] = ak_quat_mul(qa[i], qb[i]); sink = qo[N / 2].x;)
LOOP_PAIR(rot, for (int i = 0; i < N; ++i) vo[i] = ak_quat_rotate(qa[i], va[i]); sink = vo[N / 2].x;)
LOOP_PAIR(norm, for (int i = 0; i < N; ++i) qo[i] = ak_quat_normalize(qb[i]); sink = qo[N / 2].x;)
LOOP_PAIR(m4, for (int i = 0; i < N; ++i) mo[i] = ak_mat4_mul(ma[i], mb[i]); sink = mo[N / 2].m[5];)

static void arr_qmul(void) {
    ak_quat_mul_array((ak_quat_cspan){qa, N}, (ak_quat_cspan){qb, N}, (ak_quat_span){qo, N});
    sink = qo[N / 2].x;
}
static void arr_rot(void) {
    ak_quat_rotate_array((ak_quat_cspan){qa, N}, (ak_vec3_cspan){va, N}, (ak_vec3_span){vo, N});
    sink = vo[N / 2].x;
}
static void arr_norm(void) {
    ak_quat_normalize_array((ak_quat_cspan){qb, N}, (ak_quat_span){qo, N});
    sink = qo[N / 2].x;
}
static void arr_m4(void) {
    ak_mat4_mul_array((ak_mat4_cspan){ma, N}, (ak_mat4_cspan){mb, N}, (ak_mat4_span){mo, N});
    sink = mo[N / 2].m[5];
}
static void loop_slerp(void) { for (int i = 0; i < N; ++i) qo[i] = ak_quat_slerp(qa[i], qb[i], ts[i]); sink = qo[N / 2].x; }
static void loop_nlerp(void) { for (int i = 0; i < N; ++i) qo[i] = ak_quat_nlerp(qa[i], qb[i], ts[i]); sink = qo[N / 2].x; }
static void loop_polar(void) {
    float acc = 0.0f;
    for (int i = 0; i < N; ++i) acc += ak_mat3_polar(m3[i]).rotation.m[0];
    sink = acc;
}
static void loop_euler(void) {
    float acc = 0.0f;
    for (int i = 0; i < N; ++i) acc += ak_quat_to_euler(qa[i], (ak_euler_order)(i % 12), AK_EULER_INTRINSIC).x;
    sink = acc;
}

/* Three kernels alternating, best of REPS each: scalar loop, build-flags loop, array function. */
static void row(const char* what, void (*scalar)(void), void (*loop)(void), void (*arr)(void), int inner) {
    double t[3] = {1e30, 1e30, 1e30};
    void (*fn[3])(void) = {scalar, loop, arr};
    for (int r = 0; r < REPS; ++r)
        for (int k = 0; k < 3; ++k) {
            double x = time_once(fn[k], inner);
            if (x < t[k]) t[k] = x;
        }
    printf("%-20s %9.1f M/s %9.1f M/s %9.1f M/s %7.2fx %7.2fx\n", what, 1e-6 / t[0], 1e-6 / t[1], 1e-6 / t[2],
           t[0] / t[2], t[1] / t[2]);
}

int main(void) {
    ak_rng g = ak_rng_make(2024);
    for (int i = 0; i < N; ++i) {
        qa[i] = ak_quat_normalize(ak_quat_make(ak_rng_range(&g, -1, 1), ak_rng_range(&g, -1, 1), ak_rng_range(&g, -1, 1), ak_rng_range(&g, -1, 1)));
        qb[i] = ak_quat_make(ak_rng_range(&g, -1, 1), ak_rng_range(&g, -1, 1), ak_rng_range(&g, -1, 1), ak_rng_range(&g, -1, 1));
        va[i] = ak_vec3_make(ak_rng_range(&g, -5, 5), ak_rng_range(&g, -5, 5), ak_rng_range(&g, -5, 5));
        ts[i] = ak_rng_float(&g);
        for (int k = 0; k < 16; ++k) ma[i].m[k] = ak_rng_range(&g, -1, 1), mb[i].m[k] = ak_rng_range(&g, -1, 1);
        for (int k = 0; k < 9; ++k) m3[i].m[k] = ak_rng_range(&g, -1, 1);
    }
#ifndef AK_BENCH_C_FLAGS
#define AK_BENCH_C_FLAGS "unknown"
#endif
    /* the column label: the last -O flag the build passed (the one the compiler obeys) */
    char opt[8] = "-O?";
    for (const char* f = strstr(AK_BENCH_C_FLAGS, "-O"); f; f = strstr(f + 2, "-O"))
        snprintf(opt, sizeof opt, "%.3s", f);
    char col[24], ratio[16];
    snprintf(col, sizeof col, "%s loop", opt);
    snprintf(ratio, sizeof ratio, "arr/%s", opt + 1);
    printf("bench_math: %d elements per call, best of %d runs; array path = %s; C flags \"%s\"\n", N, REPS,
           AK_SIMD_NAME, AK_BENCH_C_FLAGS);
    printf("%-20s %13s %13s %13s %8s %8s\n", "operation", "scalar loop", col, "array func", "arr/scl", ratio);
    row("quat products", novec_qmul, loop_qmul, arr_qmul, 200);
    row("vec3 rotations", novec_rot, loop_rot, arr_rot, 200);
    row("quat normalizations", novec_norm, loop_norm, arr_norm, 200);
    row("4x4 products", novec_m4, loop_m4, arr_m4, 50);
    double ts_slerp, ts_nlerp, t_polar, t_euler;
    time_pair(loop_slerp, loop_nlerp, 20, &ts_slerp, &ts_nlerp);
    printf("%-20s %9.1f M/s   (nlerp %.1f M/s, slerp/nlerp time %.2fx)\n", "SLERPs", 1e-6 / ts_slerp,
           1e-6 / ts_nlerp, ts_slerp / ts_nlerp);
    time_pair(loop_polar, loop_euler, 2, &t_polar, &t_euler);
    printf("%-20s %9.2f M/s\n", "3x3 polar decomps", 1e-6 / t_polar);
    printf("%-20s %9.2f M/s\n", "quat -> Euler", 1e-6 / t_euler);
    return 0;
}
