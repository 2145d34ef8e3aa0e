/* Every noise basis of animkit beside FastNoiseLite (scalar per point) and FastNoise2 (AVX2,
 * AVX-512), issue 32; run.sh builds and runs it. One process,
 * interleaved rounds (order reversed on odd rounds), thread CPU time of one pass, 1M points
 * (3D: 128x128x64 lattice, 2D: 1024x1024, spacing 0.173), single thread. Prints the median
 * ns/point and, per group, the median of the per-round ratios ak / peer with their range.
 * Built with -DAK_AB_OLD (run.sh does when AB_BASE names another build's noise objects, their
 * symbols renamed old_*), every group also times that build's jobs ("old ak job", lib 4) in the
 * same rounds and prints new / old and old / FN2 ratios. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <animkit/noise.h>

void fnl_run(int kind, int octaves, int dims, int n, const float* x, const float* y, const float* z, float* out);
void fn2_run(int kind, int octaves, int simd, int dims, int n, const float* x, const float* y, const float* z, float* out);
const char* fn2_simd_name(int kind, int simd);
#if defined(AK_AB_OLD)
ak_result old_ak_noise_job_run(const ak_noise_job* job);
#endif

enum { N = 1 << 20, MAXV = 128, MAXR = 64 };
static float *X, *Y, *Z, *X2, *Y2;
static ak_noise AKN;

static double cpu_s(void) { struct timespec t; clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }

/* lib 0: ak per-point call, 1: ak batch job (simd 0 scalar, 1 AVX2, 2 AVX-512), 2: FNL, 3: FN2 (simd 1 AVX2, 2 AVX-512),
 * 4: the old build's batch job (AK_AB_OLD)
 * kind 0 perlin, 1 simplex, 3 value, 4 worley F1 / cellular distance, 5 FN2/FNL cellular value (ak: worley F1) */
typedef struct { char name[64]; int lib, kind, oct, simd, dims; float* out; double t[MAXR]; } variant;

static ak_noise_basis basis_of(int kind) {
    return kind == 0 ? AK_NOISE_BASIS_PERLIN : kind == 1 ? AK_NOISE_BASIS_SIMPLEX : kind == 3 ? AK_NOISE_BASIS_VALUE : AK_NOISE_BASIS_WORLEY;
}

static void run(variant* v) {
    const float *x = v->dims == 2 ? X2 : X, *y = v->dims == 2 ? Y2 : Y, *z = Z;
    float* o = v->out;
    if (v->lib == 0) {
        const ak_noise_basis b = basis_of(v->kind);
        if (v->oct == 1) {
            if (v->dims == 3) {
                if (b == AK_NOISE_BASIS_PERLIN) for (int i = 0; i < N; ++i) o[i] = ak_noise_perlin3(&AKN, x[i], y[i], z[i], NULL);
                else if (b == AK_NOISE_BASIS_SIMPLEX) for (int i = 0; i < N; ++i) o[i] = ak_noise_simplex3(&AKN, x[i], y[i], z[i], NULL);
                else if (b == AK_NOISE_BASIS_VALUE) for (int i = 0; i < N; ++i) { const float p[3] = {x[i], y[i], z[i]}; o[i] = ak_noise_value(&AKN, 3, p, NULL); }
                else for (int i = 0; i < N; ++i) { const float p[3] = {x[i], y[i], z[i]}; o[i] = ak_noise_worley(&AKN, 3, p, NULL, NULL); }
            } else {
                if (b == AK_NOISE_BASIS_PERLIN) for (int i = 0; i < N; ++i) o[i] = ak_noise_perlin2(&AKN, x[i], y[i], NULL);
                else if (b == AK_NOISE_BASIS_SIMPLEX) for (int i = 0; i < N; ++i) o[i] = ak_noise_simplex2(&AKN, x[i], y[i], NULL);
                else if (b == AK_NOISE_BASIS_VALUE) for (int i = 0; i < N; ++i) { const float p[2] = {x[i], y[i]}; o[i] = ak_noise_value(&AKN, 2, p, NULL); }
                else for (int i = 0; i < N; ++i) { const float p[2] = {x[i], y[i]}; o[i] = ak_noise_worley(&AKN, 2, p, NULL, NULL); }
            }
        } else {
            ak_fractal_desc fd = {.type = AK_FRACTAL_FBM, .basis = b, .octaves = (uint32_t)v->oct, .lacunarity = 2, .gain = 0.5f, .frequency = 1};
            for (int i = 0; i < N; ++i) { float p[3] = {x[i], y[i], v->dims == 3 ? z[i] : 0}; o[i] = ak_fractal_eval(&AKN, &fd, (uint32_t)v->dims, p, NULL); }
        }
    } else if (v->lib == 1 || v->lib == 4) {
        ak_noise_job job = {.noise = &AKN,
                            .fractal = {.type = AK_FRACTAL_FBM, .basis = basis_of(v->kind), .octaves = (uint32_t)v->oct,
                                        .lacunarity = 2, .gain = 0.5f, .frequency = 1},
                            .dimensions = (uint32_t)v->dims, .x = {x, N}, .y = {y, N}, .z = {v->dims == 3 ? z : NULL, N},
                            .out_values = {o, N}, .thread_count = 1,
                            .simd_limit = v->simd == 0 ? AK_NOISE_SIMD_SCALAR : v->simd == 1 ? AK_NOISE_SIMD_AVX2 : AK_NOISE_SIMD_AVX512};
#if defined(AK_AB_OLD)
        if (v->lib == 4) {
            if (old_ak_noise_job_run(&job) != AK_OK) { fprintf(stderr, "old ak job failed\n"); exit(1); }
            return;
        }
#endif
        if (ak_noise_job_run(&job) != AK_OK) { fprintf(stderr, "ak job failed\n"); exit(1); }
    } else if (v->lib == 2) {
        fnl_run(v->kind, v->oct, v->dims, N, x, y, z, o);
    } else {
        fn2_run(v->kind, v->oct, v->simd == 1 ? 1 : 0, v->dims, N, x, y, z, o);
    }
}

static int cmpd(const void* a, const void* b) { double x = *(const double*)a, y = *(const double*)b; return (x > y) - (x < y); }
static double med(const double* t, int r, double* lo, double* hi) {
    double s[MAXR]; memcpy(s, t, sizeof(double) * r); qsort(s, r, sizeof(double), cmpd);
    *lo = s[0]; *hi = s[r - 1]; return r & 1 ? s[r / 2] : 0.5 * (s[r / 2 - 1] + s[r / 2]);
}

static variant vs[MAXV];
static int nv = 0;
static void add(const char* grp, const char* what, int lib, int kind, int oct, int simd, int dims) {
    variant* v = &vs[nv++];
    snprintf(v->name, sizeof v->name, "%s %s", grp, what);
    v->lib = lib, v->kind = kind, v->oct = oct, v->simd = simd, v->dims = dims;
}
static int find(int lib, int kind, int oct, int simd, int dims) {
    for (int i = 0; i < nv; ++i)
        if (vs[i].lib == lib && vs[i].kind == kind && vs[i].oct == oct && vs[i].simd == simd && vs[i].dims == dims && vs[i].out) return i;
    return -1;
}

int main(int argc, char** argv) {
    int R = argc > 1 ? atoi(argv[1]) : 5;
    if (R < 1 || R > MAXR) R = 5;
    const char* only = argc > 2 ? argv[2] : "";
    X = malloc(sizeof(float) * N); Y = malloc(sizeof(float) * N); Z = malloc(sizeof(float) * N);
    X2 = malloc(sizeof(float) * N); Y2 = malloc(sizeof(float) * N);
    for (int k = 0, i = 0; k < 64; ++k) for (int j = 0; j < 128; ++j) for (int l = 0; l < 128; ++l, ++i) {
        X[i] = 0.05f + 0.173f * l; Y[i] = 0.11f + 0.173f * j; Z[i] = 0.07f + 0.173f * k;
    }
    for (int i = 0; i < N; ++i) { X2[i] = 0.05f + 0.173f * (float)(i % 1024); Y2[i] = 0.11f + 0.173f * (float)(i / 1024); }
    AKN = ak_noise_make(1);
    struct { const char* g; int kind, oct, dims; } groups[] = {
        {"value3", 3, 1, 3}, {"value2", 3, 1, 2}, {"worley3", 4, 1, 3}, {"worley2", 4, 1, 2},
        {"fbm5-value3", 3, 5, 3}, {"fbm5-worley3", 4, 5, 3}, {"perlin3", 0, 1, 3}, {"simplex3", 1, 1, 3},
        {"fbm5-perlin3", 0, 5, 3}, {"fbm5-simplex3", 1, 5, 3}};
    for (size_t gi = 0; gi < sizeof groups / sizeof groups[0]; ++gi) {
        const char* g = groups[gi].g; const int k = groups[gi].kind, o = groups[gi].oct, d = groups[gi].dims;
        if (*only && !strstr(g, only)) continue;
        add(g, o == 1 ? "ak per-point call" : "ak_fractal_eval loop", 0, k, o, 0, d);
        add(g, "ak job scalar", 1, k, o, 0, d);
        add(g, "ak job AVX2", 1, k, o, 1, d);
        add(g, "ak job AVX-512", 1, k, o, 2, d);
#if defined(AK_AB_OLD)
        add(g, "old ak job AVX2", 4, k, o, 1, d);
        add(g, "old ak job AVX-512", 4, k, o, 2, d);
#endif
        add(g, k == 4 ? "FNL Cellular distance" : "FastNoiseLite", 2, k, o, 0, d);
        add(g, k == 4 ? "FN2 CellularDistance AVX2" : "FastNoise2 AVX2", 3, k, o, 1, d);
        add(g, k == 4 ? "FN2 CellularDistance AVX-512" : "FastNoise2 AVX-512", 3, k, o, 2, d);
        if (k == 4) {
            add(g, "FNL Cellular cell value", 2, 5, o, 0, d);
            add(g, "FN2 CellularValue AVX2", 3, 5, o, 1, d);
            add(g, "FN2 CellularValue AVX-512", 3, 5, o, 2, d);
        }
    }
    for (int a = 0; a < nv; ++a) { vs[a].out = malloc(sizeof(float) * N); run(&vs[a]); } /* warm-up */
    printf("FastNoise2 feature sets: Max -> %s, AVX2 -> %s; animkit widest kernel: %s\n", fn2_simd_name(0, 0), fn2_simd_name(0, 1), ak_noise_simd_name());
    for (int r = 0; r < R; ++r)
        for (int a = 0; a < nv; ++a) {
            variant* v = &vs[r & 1 ? nv - 1 - a : a];
            double t0 = cpu_s(); run(v); v->t[r] = cpu_s() - t0;
        }
    printf("%d points, %d rounds, single thread, thread CPU time, median [min-max] ns/point\n", N, R);
    for (int a = 0; a < nv; ++a) {
        double lo, hi, m = med(vs[a].t, R, &lo, &hi);
        printf("  %-44s %8.2f [%6.2f - %6.2f]\n", vs[a].name, 1e9 * m / N, 1e9 * lo / N, 1e9 * hi / N);
    }
    printf("ratios (ak time / peer time; median of per-round ratios [min-max]; <= 1.00 meets the target)\n");
    for (int a = 0; a < nv; ++a) {
        variant* v = &vs[a];
        if (v->lib == 2 || v->lib == 3) continue;
        int peers[3] = {-1, -1, -1}; /* ak call vs FNL (kind, kind 5); ak job AVX2/512 vs FN2 same width */
        if (v->lib == 0) { peers[0] = find(2, v->kind, v->oct, 0, v->dims); if (v->kind == 4) peers[1] = find(2, 5, v->oct, 0, v->dims); }
        else if (v->simd > 0) { peers[0] = find(3, v->kind, v->oct, v->simd, v->dims); if (v->kind == 4) peers[1] = find(3, 5, v->oct, v->simd, v->dims); }
        if (v->lib == 1 && v->simd > 0) peers[2] = find(4, v->kind, v->oct, v->simd, v->dims); /* new / old */
        for (int p = 0; p < 3; ++p) {
            if (peers[p] < 0) continue;
            double rr[MAXR], lo, hi;
            for (int r = 0; r < R; ++r) rr[r] = v->t[r] / vs[peers[p]].t[r];
            const double m = med(rr, R, &lo, &hi);
            printf("  %-36s / %-32s %5.2f [%4.2f-%4.2f] %s\n", v->name, vs[peers[p]].name, m, lo, hi, m <= 1.0 ? "met" : "NOT met");
        }
    }
    /* exactness: every ak job path of a group against the scalar job */
    for (int a = 0; a < nv; ++a) {
        variant* v = &vs[a];
        if ((v->lib != 1 && v->lib != 4) || v->simd == 0) continue;
        const int s = find(1, v->kind, v->oct, 0, v->dims);
        int diff = 0; for (int i = 0; i < N; ++i) diff += memcmp(&v->out[i], &vs[s].out[i], 4) != 0;
        printf("check: '%s' vs scalar job: %d of %d values differ\n", v->name, diff, N);
    }
    return 0;
}
