/* bench/vs_noise: ../shared/peers/noise/noise_bench.c with animkit's batch job on each SIMD
 * path chosen explicitly (simd 0 scalar, 1 AVX2, 2 AVX-512 through job.simd_limit) and simplex
 * batch rows for the SIMD paths. Same data, sizes and timing as the peers' harness.
 *
 * animkit noise vs FastNoiseLite (and FastNoise2 when HAVE_FN2), one process, interleaved:
 * every round runs every variant once, order reversed on odd rounds. 1M points = 128x128x64
 * lattice at spacing 0.173 (non-integer, so points are not on noise lattice points), SoA.
 * Rate = points / thread CPU time of one pass (single thread). Median and [min, max] of R rounds. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <animkit/noise.h>

void fnl_run(int kind, int octaves, int n, const float* x, const float* y, const float* z, float* out);
void fnl_run_generic(int kind, int octaves, int n, const float* x, const float* y, const float* z, float* out);
#ifdef HAVE_FN2
void fn2_run(int kind, int octaves, int simd, int n, const float* x, const float* y, const float* z, float* out);
const char* fn2_simd_name(int kind, int simd);
#endif

enum { NX = 128, NY = 128, NZ = 64, N = NX * NY * NZ, MAXV = 40 };
static float *X, *Y, *Z;
static ak_noise AKN;

static double cpu_s(void) { struct timespec t; clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }

typedef struct { const char* name; int lib, kind, oct, simd; float* out; double t[64]; } variant;
/* lib 0: ak per-point call, 1: ak batch job, 2: FNL, 3: FN2. kind 0 perlin, 1 simplex/OpenSimplex2, 2 OpenSimplex2S/SuperSimplex */

static void run(variant* v) {
    if (v->lib == 0) {
        float* o = v->out;
        if (v->oct == 1) {
            if (v->kind == 0) for (int i = 0; i < N; ++i) o[i] = ak_noise_perlin3(&AKN, X[i], Y[i], Z[i], NULL);
            else for (int i = 0; i < N; ++i) o[i] = ak_noise_simplex3(&AKN, X[i], Y[i], Z[i], NULL);
        } else {
            ak_fractal_desc fd = {.type = AK_FRACTAL_FBM, .basis = v->kind == 0 ? AK_NOISE_BASIS_PERLIN : AK_NOISE_BASIS_SIMPLEX,
                                  .octaves = (uint32_t)v->oct, .lacunarity = 2, .gain = 0.5f, .frequency = 1};
            for (int i = 0; i < N; ++i) { float p[3] = {X[i], Y[i], Z[i]}; o[i] = ak_fractal_eval(&AKN, &fd, 3, p, NULL); }
        }
    } else if (v->lib == 1) {
        ak_noise_job job = {.noise = &AKN,
                            .fractal = {.type = AK_FRACTAL_FBM, .basis = v->kind == 0 ? AK_NOISE_BASIS_PERLIN : AK_NOISE_BASIS_SIMPLEX,
                                        .octaves = (uint32_t)v->oct, .lacunarity = 2, .gain = 0.5f, .frequency = 1},
                            .dimensions = 3, .x = {X, N}, .y = {Y, N}, .z = {Z, N}, .out_values = {v->out, N},
                            .thread_count = 1,
                            .simd_limit = v->simd == 0 ? AK_NOISE_SIMD_SCALAR : v->simd == 1 ? AK_NOISE_SIMD_AVX2 : AK_NOISE_SIMD_AVX512};
        if (ak_noise_job_run(&job) != AK_OK) { fprintf(stderr, "ak job failed\n"); exit(1); }
    } else if (v->lib == 2) {
        fnl_run(v->kind, v->oct, N, X, Y, Z, v->out);
    } else if (v->lib == 4) {
        fnl_run_generic(v->kind, v->oct, N, X, Y, Z, v->out);
#ifdef HAVE_FN2
    } else {
        fn2_run(v->kind, v->oct, v->simd, N, X, Y, Z, v->out);
#endif
    }
}

static int cmpd(const void* a, const void* b) { double x = *(const double*)a, y = *(const double*)b; return (x > y) - (x < y); }
static double med(const double* t, int r, double* lo, double* hi) {
    double s[64]; memcpy(s, t, sizeof(double) * r); qsort(s, r, sizeof(double), cmpd);
    *lo = s[0]; *hi = s[r - 1]; return r & 1 ? s[r / 2] : 0.5 * (s[r / 2 - 1] + s[r / 2]);
}

int main(int argc, char** argv) {
    int R = argc > 1 ? atoi(argv[1]) : 7;
    const char* only = argc > 2 ? argv[2] : "";
    X = malloc(sizeof(float) * N); Y = malloc(sizeof(float) * N); Z = malloc(sizeof(float) * N);
    for (int k = 0, i = 0; k < NZ; ++k) for (int j = 0; j < NY; ++j) for (int l = 0; l < NX; ++l, ++i) {
        X[i] = 0.05f + 0.173f * l; Y[i] = 0.11f + 0.173f * j; Z[i] = 0.07f + 0.173f * k;
    }
    AKN = ak_noise_make(1);
    variant vs[MAXV]; int nv = 0;
#define V(nm, l, k, o, s) vs[nv++] = (variant){nm, l, k, o, s, NULL, {0}}
    V("perlin  ak_noise_perlin3 loop", 0, 0, 1, 0);
    V("perlin  ak job scalar", 1, 0, 1, 0);
    V("perlin  ak job AVX2", 1, 0, 1, 1);
    V("perlin  ak job AVX512", 1, 0, 1, 2);
    V("perlin  FastNoiseLite", 2, 0, 1, 0);
    V("perlin  FastNoiseLite generic -O3", 4, 0, 1, 0);
#ifdef HAVE_FN2
    V("perlin  FastNoise2 AVX2", 3, 0, 1, 1);
    V("perlin  FastNoise2 AVX512", 3, 0, 1, 0);
#endif
    V("simplex ak_noise_simplex3 loop", 0, 1, 1, 0);
    V("simplex ak job scalar", 1, 1, 1, 0);
    V("simplex ak job AVX2", 1, 1, 1, 1);
    V("simplex ak job AVX512", 1, 1, 1, 2);
    V("simplex FNL OpenSimplex2", 2, 1, 1, 0);
    V("simplex FNL OpenSimplex2S", 2, 2, 1, 0);
#ifdef HAVE_FN2
    V("simplex FN2 Simplex AVX2", 3, 1, 1, 1);
    V("simplex FN2 Simplex AVX512", 3, 1, 1, 0);
    V("simplex FN2 SuperSimplex AVX2", 3, 2, 1, 1);
#endif
    V("fbm5 perlin  ak_fractal_eval loop", 0, 0, 5, 0);
    V("fbm5 perlin  ak job scalar", 1, 0, 5, 0);
    V("fbm5 perlin  ak job AVX2", 1, 0, 5, 1);
    V("fbm5 perlin  ak job AVX512", 1, 0, 5, 2);
    V("fbm5 perlin  FastNoiseLite", 2, 0, 5, 0);
    V("fbm5 perlin  FastNoiseLite generic -O3", 4, 0, 5, 0);
#ifdef HAVE_FN2
    V("fbm5 perlin  FastNoise2 AVX2", 3, 0, 5, 1);
    V("fbm5 perlin  FastNoise2 AVX512", 3, 0, 5, 0);
#endif
    V("fbm5 simplex ak_fractal_eval loop", 0, 1, 5, 0);
    V("fbm5 simplex ak job scalar", 1, 1, 5, 0);
    V("fbm5 simplex ak job AVX2", 1, 1, 5, 1);
    V("fbm5 simplex ak job AVX512", 1, 1, 5, 2);
    V("fbm5 simplex FNL OpenSimplex2", 2, 1, 5, 0);
#ifdef HAVE_FN2
    V("fbm5 simplex FN2 Simplex AVX2", 3, 1, 5, 1);
    V("fbm5 simplex FN2 Simplex AVX512", 3, 1, 5, 0);
#endif
    int act[MAXV], na = 0;
    for (int i = 0; i < nv; ++i) if (!*only || strstr(vs[i].name, only)) act[na++] = i;
    for (int a = 0; a < na; ++a) { vs[act[a]].out = malloc(sizeof(float) * N); run(&vs[act[a]]); } /* warm-up */
#ifdef HAVE_FN2
    printf("FastNoise2 active feature sets: Max -> %s, AVX2 -> %s\n", fn2_simd_name(0, 0), fn2_simd_name(0, 1));
#endif
    printf("ak_noise_simd_name: %s\n", ak_noise_simd_name());
    for (int r = 0; r < R; ++r)
        for (int a = 0; a < na; ++a) {
            variant* v = &vs[act[r & 1 ? na - 1 - a : a]];
            double t0 = cpu_s(); run(v); v->t[r] = cpu_s() - t0;
        }
    printf("%d points (128x128x64, spacing 0.173), %d rounds, single thread, thread CPU time\n", N, R);
    printf("%-34s %9s %19s %8s %8s %8s %8s\n", "variant", "Msamp/s", "[min-max]", "ns/pt", "mean", "std", "maxabs");
    for (int a = 0; a < na; ++a) {
        variant* v = &vs[act[a]]; double lo, hi, m = med(v->t, R, &lo, &hi);
        double s = 0, s2 = 0, mx = 0;
        for (int i = 0; i < N; ++i) { s += v->out[i]; s2 += (double)v->out[i] * v->out[i]; if (fabs(v->out[i]) > mx) mx = fabs(v->out[i]); }
        double mean = s / N, sd = sqrt(s2 / N - mean * mean);
        printf("%-34s %9.1f [%7.1f - %7.1f] %8.2f %8.4f %8.4f %8.4f\n", v->name, N / m / 1e6, N / hi / 1e6, N / lo / 1e6, 1e9 * m / N, mean, sd, mx);
    }
    /* exactness: ak loop vs ak batch jobs */
    for (int a = 0; a < na; ++a) for (int b = 0; b < na; ++b) {
        variant *p = &vs[act[a]], *q = &vs[act[b]];
        if (a < b && p->lib <= 1 && q->lib <= 1 && p->kind == q->kind && p->oct == q->oct) {
            int diff = 0; for (int i = 0; i < N; ++i) diff += p->out[i] != q->out[i];
            printf("check: '%s' vs '%s': %d of %d values differ\n", p->name, q->name, diff, N);
        }
    }
    return 0;
}
