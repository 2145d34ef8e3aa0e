/* bench_blendshape: 50 targets on a 30,000-vertex mesh, dense vs sparse storage, against a naive
 * scalar loop, all measured side by side in one run. Rates are vertices x targets per second
 * (the nominal work V * K of one blend, whatever the storage skips). Fixed seed.
 *
 * Usage: bench_blendshape [vertex_count] [target_count] [moved_percent] */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_clock.h"

#include <animkit/blendshape.h>

/* The textbook loop: for each vertex, p = b_0 + sum_k w_k d_k, deltas target-major. */
static void naive_blend(const ak_vec3* base, const ak_vec3* deltas, const float* w, size_t k_count, size_t v,
                        ak_vec3* out) {
    for (size_t i = 0; i < v; ++i) {
        ak_vec3 p = base[i];
        for (size_t k = 0; k < k_count; ++k) {
            const ak_vec3 d = deltas[k * v + i];
            p.x += w[k] * d.x;
            p.y += w[k] * d.y;
            p.z += w[k] * d.z;
        }
        out[i] = p;
    }
}

/* The same with normals: n = n_0 + sum_k w_k dn_k, renormalised ((0, 1, 0) when it vanishes). */
static void naive_blend_normals(const ak_vec3* base, const ak_vec3* normals, const ak_vec3* deltas,
                                const ak_vec3* ndeltas, const float* w, size_t k_count, size_t v, ak_vec3* out,
                                ak_vec3* out_n) {
    for (size_t i = 0; i < v; ++i) {
        ak_vec3 p = base[i], n = normals[i];
        for (size_t k = 0; k < k_count; ++k) {
            const ak_vec3 d = deltas[k * v + i], dn = ndeltas[k * v + i];
            p.x += w[k] * d.x;
            p.y += w[k] * d.y;
            p.z += w[k] * d.z;
            n.x += w[k] * dn.x;
            n.y += w[k] * dn.y;
            n.z += w[k] * dn.z;
        }
        const float l = sqrtf(n.x * n.x + n.y * n.y + n.z * n.z);
        out[i] = p;
        out_n[i] = l > 1e-20f ? ak_vec3_make(n.x / l, n.y / l, n.z / l) : ak_vec3_make(0.0f, 1.0f, 0.0f);
    }
}

typedef struct bench_ctx {
    size_t v, k;
    const ak_vec3 *base, *normals, *deltas, *ndeltas;
    const float* w;
    ak_vec3 *out, *out_n;
    const ak_blendshape_set* set;
    int mode; /* 0 naive, 1 dense job, 2 set (positions), 3 set (positions + normals),
                 4 naive (positions + normals) */
} bench_ctx;

static void run_once(const bench_ctx* c) {
    switch (c->mode) {
    case 0:
        naive_blend(c->base, c->deltas, c->w, c->k, c->v, c->out);
        break;
    case 4:
        naive_blend_normals(c->base, c->normals, c->deltas, c->ndeltas, c->w, c->k, c->v, c->out, c->out_n);
        break;
    case 1: {
        ak_blendshape_dense_job j = {.weights = {c->w, c->k}, .base_positions = {c->base, c->v},
                                     .deltas = {c->deltas, c->k * c->v}, .out_positions = {c->out, c->v}};
        if (ak_blendshape_dense_run(&j) != AK_OK) abort();
        break;
    }
    default: {
        ak_blendshape_job j = {.set = c->set, .weights = {c->w, c->k}, .base_positions = {c->base, c->v},
                               .out_positions = {c->out, c->v}};
        if (c->mode == 3) {
            j.base_normals = (ak_vec3_cspan){c->normals, c->v};
            j.out_normals = (ak_vec3_span){c->out_n, c->v};
        }
        if (ak_blendshape_run(&j) != AK_OK) abort();
        break;
    }
    }
}

/* Iterations that take at least ~0.1 s (5 ms under AK_BENCH_QUICK). */
static int calibrate(const bench_ctx* c) {
    int iters = 1;
    for (;;) {
        double t0 = bench_wall_s();
        for (int i = 0; i < iters; ++i) run_once(c);
        if (bench_wall_s() - t0 > (bench_quick() ? 0.005 : 0.1) || iters >= (1 << 20)) return iters;
        iters *= 2;
    }
}

/* Seconds per blend for each context, best of `rounds`, the contexts taking turns within every
 * round so that a busy machine slows them all alike (the ratios are what carry over). */
static void time_blends(const bench_ctx* c, size_t count, int rounds, double* out_best) {
    int iters[16];
    for (size_t m = 0; m < count; ++m) {
        iters[m] = calibrate(&c[m]);
        out_best[m] = 1e30;
    }
    for (int r = 0; r < rounds; ++r)
        for (size_t m = 0; m < count; ++m) {
            double t0 = bench_wall_s();
            for (int i = 0; i < iters[m]; ++i) run_once(&c[m]);
            double t = (bench_wall_s() - t0) / iters[m];
            if (t < out_best[m]) out_best[m] = t;
        }
}

static void fill(ak_vec3* d, size_t n, ak_rng* rng, float s) {
    for (size_t i = 0; i < n; ++i) { /* three statements: a fixed draw order on every compiler */
        float x = ak_rng_range(rng, -s, s);
        float y = ak_rng_range(rng, -s, s);
        float z = ak_rng_range(rng, -s, s);
        d[i] = ak_vec3_make(x, y, z);
    }
}

/* Each target moves a contiguous run of `moved` vertices (a local target: blink, smile). */
static void fill_local(ak_vec3* d, ak_vec3* nd, size_t k_count, size_t v, size_t moved, ak_rng* rng) {
    memset(d, 0, k_count * v * sizeof(ak_vec3));
    memset(nd, 0, k_count * v * sizeof(ak_vec3));
    for (size_t k = 0; k < k_count; ++k) {
        size_t start = moved < v ? (size_t)(ak_rng_float(rng) * (float)(v - moved)) : 0;
        fill(d + k * v + start, moved, rng, 0.05f);
        fill(nd + k * v + start, moved, rng, 0.2f);
    }
}

static ak_blendshape_set* make_set(size_t v, size_t k, const ak_vec3* d, const ak_vec3* nd, ak_blendshape_storage s) {
    ak_blendshape_set* set = NULL;
    ak_blendshape_set_desc desc = {.vertex_count = v, .target_count = k, .deltas = {d, k * v},
                                   .normal_deltas = {nd, k * v}, .storage = s};
    if (ak_blendshape_set_create(&desc, NULL, &set) != AK_OK) abort();
    return set;
}

int main(int argc, char** argv) {
    const size_t v = argc > 1 ? (size_t)atol(argv[1]) : 30000;
    const size_t k = argc > 2 ? (size_t)atol(argv[2]) : 50;
    const double pct = argc > 3 ? atof(argv[3]) : 10.0;
    if (v == 0 || k == 0 || !(pct > 0.0 && pct <= 100.0)) {
        fprintf(stderr, "usage: bench_blendshape [vertex_count > 0] [target_count > 0] [moved_percent in (0,100]]\n");
        return 2;
    }
    const size_t moved = (size_t)(v * pct / 100.0);
    ak_rng rng = ak_rng_make(2024);
    ak_vec3* base = malloc(v * sizeof(ak_vec3));
    ak_vec3* normals = malloc(v * sizeof(ak_vec3));
    ak_vec3* out = malloc(v * sizeof(ak_vec3));
    ak_vec3* out_n = malloc(v * sizeof(ak_vec3));
    ak_vec3* ref = malloc(v * sizeof(ak_vec3));
    ak_vec3* d = malloc(k * v * sizeof(ak_vec3));
    ak_vec3* nd = malloc(k * v * sizeof(ak_vec3));
    float* w = malloc(k * sizeof(float));
    if (!base || !normals || !out || !out_n || !ref || !d || !nd || !w) return 1;
    fill(base, v, &rng, 1.0f);
    for (size_t i = 0; i < v; ++i) normals[i] = ak_vec3_normalize(ak_vec3_add(base[i], ak_vec3_make(0, 0, 0.1f)));
    fill_local(d, nd, k, v, moved, &rng);
    for (size_t i = 0; i < k; ++i) w[i] = ak_rng_range(&rng, 0.05f, 1.0f); /* every target active */

    ak_blendshape_set* dense = make_set(v, k, d, nd, AK_BLENDSHAPE_STORAGE_DENSE);
    ak_blendshape_set* sparse = make_set(v, k, d, nd, AK_BLENDSHAPE_STORAGE_SPARSE);
    const double work = (double)v * (double)k;

    printf("bench_blendshape: %zu vertices, %zu targets, %.1f%% of vertices moved per target "
#ifdef AK_NO_SIMD
           "(AK_NO_SIMD build)\n",
#else
           "(SIMD build)\n",
#endif
           v, k, pct);
    printf("set memory: dense %.1f MiB, sparse %.1f MiB (positions + normals)\n",
           ak_blendshape_set_memory_size(dense) / 1048576.0, ak_blendshape_set_memory_size(sparse) / 1048576.0);

    struct {
        const char* name;
        int mode;
        const ak_blendshape_set* set;
    } rows[] = {
        {"naive scalar loop (vertex-major)", 0, NULL},
        {"naive scalar loop, + normals", 4, NULL},
        {"dense job (raw target-major deltas)", 1, NULL},
        {"set, dense storage", 2, NULL},
        {"set, sparse storage", 2, NULL},
        {"set, dense storage, + normals", 3, NULL},
        {"set, sparse storage, + normals", 3, NULL},
    };
    rows[3].set = dense, rows[4].set = sparse, rows[5].set = dense, rows[6].set = sparse;
    /* reference results for the check below: positions, and normals from the naive normals loop */
    ak_vec3* ref_n = malloc(v * sizeof(ak_vec3));
    if (!ref_n) return 1;
    bench_ctx c0 = {v, k, base, normals, d, nd, w, ref, ref_n, NULL, 4};
    run_once(&c0);
    enum { ROWS = sizeof(rows) / sizeof(rows[0]) };
    bench_ctx ctx[ROWS];
    double best[ROWS];
    for (size_t r = 0; r < ROWS; ++r)
        ctx[r] = (bench_ctx){v, k, base, normals, d, nd, w, out, out_n, rows[r].set, rows[r].mode};
    time_blends(ctx, ROWS, 7, best);
    printf("(\"vs naive\": the naive loop doing the same work, positions or positions + normals, same rounds;\n"
           " max |diff|: positions, then normals, against the naive loops)\n");
    printf("%-40s %12s %14s %10s %12s %12s\n", "method", "ms/blend", "Mvert*tgt/s", "vs naive", "max |dp|",
           "max |dn|");
    for (size_t r = 0; r < ROWS; ++r) {
        const bool with_n = ctx[r].mode >= 3;
        memset(out_n, 0, v * sizeof(ak_vec3));
        run_once(&ctx[r]);
        double err = 0.0, err_n = 0.0;
        for (size_t i = 0; i < v; ++i) {
            double e = fabs(out[i].x - ref[i].x) + fabs(out[i].y - ref[i].y) + fabs(out[i].z - ref[i].z);
            double en = fabs(out_n[i].x - ref_n[i].x) + fabs(out_n[i].y - ref_n[i].y) + fabs(out_n[i].z - ref_n[i].z);
            if (e > err) err = e;
            if (en > err_n) err_n = en;
        }
        const double naive = with_n ? best[1] : best[0];
        printf("%-40s %12.3f %14.1f %9.2fx %12.2g", rows[r].name, best[r] * 1e3, work / best[r] / 1e6, naive / best[r],
               err);
        if (with_n) printf(" %12.2g", err_n);
        printf("\n");
    }
    free(ref_n);
    ak_blendshape_set_destroy(dense);
    ak_blendshape_set_destroy(sparse);

    /* Where sparse stops paying: one set per storage at several moved fractions (positions only). */
    printf("\ndense vs sparse storage by moved fraction (positions only; AUTO picks sparse at <= 33%%):\n");
    printf("%10s %14s %14s %14s\n", "moved %", "dense ms", "sparse ms", "sparse gain");
    const double fractions[] = {1, 5, 10, 25, 40, 60, 100};
    for (size_t f = 0; f < sizeof(fractions) / sizeof(fractions[0]); ++f) {
        fill_local(d, nd, k, v, (size_t)(v * fractions[f] / 100.0), &rng);
        ak_blendshape_set* sd = make_set(v, k, d, nd, AK_BLENDSHAPE_STORAGE_DENSE);
        ak_blendshape_set* ss = make_set(v, k, d, nd, AK_BLENDSHAPE_STORAGE_SPARSE);
        bench_ctx pair[2] = {{v, k, base, normals, d, nd, w, out, out_n, sd, 2},
                             {v, k, base, normals, d, nd, w, out, out_n, ss, 2}};
        double bt[2];
        time_blends(pair, 2, 5, bt);
        const double td = bt[0], ts = bt[1];
        printf("%10.0f %14.3f %14.3f %13.2fx\n", fractions[f], td * 1e3, ts * 1e3, td / ts);
        ak_blendshape_set_destroy(sd);
        ak_blendshape_set_destroy(ss);
    }
    free(base), free(normals), free(out), free(out_n), free(ref), free(d), free(nd), free(w);
    return 0;
}
