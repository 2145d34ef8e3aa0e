/* vs_rev: a revision's per-point noise (old_*) beside the working tree's (new_*) in one
 * process; vs_rev.sh builds it. Part 1 compares the bits of every value, F2 and gradient over
 * CHECK points per case; part 2 times the per-point calls (1M points, lattice-aligned as
 * bench/vs_noise/noise_bench.c and uniform random), interleaved rounds, thread CPU time. Exit
 * status 1 when any bit differs. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <animkit/noise.h>

#define DECL(P)                                                                                                     \
    ak_noise P##ak_noise_make(uint64_t seed);                                                                       \
    float P##ak_noise_perlin1(const ak_noise*, float, float*);                                                      \
    float P##ak_noise_perlin2(const ak_noise*, float, float, float*);                                               \
    float P##ak_noise_perlin3(const ak_noise*, float, float, float, float*);                                        \
    float P##ak_noise_perlin4(const ak_noise*, float, float, float, float, float*);                                 \
    float P##ak_noise_perlin_periodic(const ak_noise*, uint32_t, const float*, const int*, float*);                 \
    float P##ak_noise_simplex2(const ak_noise*, float, float, float*);                                              \
    float P##ak_noise_simplex3(const ak_noise*, float, float, float, float*);                                       \
    float P##ak_noise_value(const ak_noise*, uint32_t, const float*, float*);                                       \
    float P##ak_noise_worley(const ak_noise*, uint32_t, const float*, float*, float*);                              \
    float P##ak_noise_eval(const ak_noise*, ak_noise_basis, uint32_t, const float*, float*);                        \
    float P##ak_fractal_eval(const ak_noise*, const ak_fractal_desc*, uint32_t, const float*, float*);
DECL(old_)
DECL(new_)

/* One case: what to call and with which arguments. */
enum { K_PERLIN, K_PERIODIC, K_SIMPLEX, K_VALUE, K_WORLEY, K_EVAL, K_FRACTAL };
typedef struct {
    int kind, dims, grad, f2;
    ak_noise_basis basis;
    ak_fractal_desc fd;
    char name[64];
} ncase;

static const int PERIOD[4] = {5, 17, 256, 3};

/* out[0] value, out[1..4] gradient, out[5] F2 (unused entries stay at a fixed pattern) */
static void eval(int side, const ak_noise* n, const ncase* c, const float* p, float* out) {
    for (int k = 0; k < 6; ++k) out[k] = 123.0f;
    float* g = c->grad ? out + 1 : NULL;
    float* f2 = c->f2 ? out + 5 : NULL;
#define CALLS(P)                                                                                                    \
    switch (c->kind) {                                                                                              \
    case K_PERLIN:                                                                                                  \
        out[0] = c->dims == 1   ? P##ak_noise_perlin1(n, p[0], g)                                                   \
                 : c->dims == 2 ? P##ak_noise_perlin2(n, p[0], p[1], g)                                             \
                 : c->dims == 3 ? P##ak_noise_perlin3(n, p[0], p[1], p[2], g)                                       \
                                : P##ak_noise_perlin4(n, p[0], p[1], p[2], p[3], g);                                \
        break;                                                                                                      \
    case K_PERIODIC: out[0] = P##ak_noise_perlin_periodic(n, (uint32_t)c->dims, p, PERIOD, g); break;               \
    case K_SIMPLEX:                                                                                                 \
        out[0] = c->dims == 2 ? P##ak_noise_simplex2(n, p[0], p[1], g) : P##ak_noise_simplex3(n, p[0], p[1], p[2], g); \
        break;                                                                                                      \
    case K_VALUE: out[0] = P##ak_noise_value(n, (uint32_t)c->dims, p, g); break;                                    \
    case K_WORLEY: out[0] = P##ak_noise_worley(n, (uint32_t)c->dims, p, f2, g); break;                              \
    case K_EVAL: out[0] = P##ak_noise_eval(n, c->basis, (uint32_t)c->dims, p, g); break;                            \
    default: out[0] = P##ak_fractal_eval(n, &c->fd, (uint32_t)c->dims, p, g); break;                                \
    }
    if (side == 0) {
        CALLS(old_)
    } else {
        CALLS(new_)
    }
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t next64(void) {
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static float uni(float lo, float hi) { return lo + (hi - lo) * (float)(next64() >> 40) * (1.0f / 16777216.0f); }

/* One coordinate from a mix of the cases that matter for floor, hashing and signed zeros. */
static float coord(void) {
    const uint64_t r = next64();
    const float sgn = (r >> 8) & 1 ? -1.0f : 1.0f;
    switch (r % 16) {
    case 0: case 1: case 2: case 3: case 4: return uni(-300.0f, 300.0f);
    case 5: case 6: return uni(-4.0f, 4.0f);
    case 7: return sgn * 0.0f;                                            /* +-0 */
    case 8: return sgn * (float)((r >> 16) % 600);                        /* integers */
    case 9: return nextafterf(sgn * (float)((r >> 16) % 600), (r >> 9) & 1 ? INFINITY : -INFINITY);
    case 10: return sgn * ((float)((r >> 16) % 600) + 0.5f);              /* half-integers */
    case 11: return sgn * uni(8388608.0f, 16777300.0f);                   /* 2^23 .. past the 2^24 limit */
    case 12: return (r >> 16) % 8 == 0 ? NAN : (r >> 16) % 8 == 1 ? sgn * INFINITY : sgn * uni(0.0f, 1e-30f);
    case 13: return 0.05f + 0.173f * (float)((r >> 16) % 1024);           /* bench lattice */
    default: return uni(-1e5f, 1e5f);
    }
}

static double cpu_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
static int cmpd(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}
static double med(double* v, int n, double* lo, double* hi) {
    qsort(v, (size_t)n, sizeof(double), cmpd);
    *lo = v[0], *hi = v[n - 1];
    return n & 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

enum { MAXC = 160, TN = 1 << 20, MAXR = 64 };
static ncase cases[MAXC];
static int ncases = 0;
static ncase* add(int kind, int dims, int grad, int f2, ak_noise_basis b, const char* fmt) {
    ncase* c = &cases[ncases++];
    memset(c, 0, sizeof *c);
    c->kind = kind, c->dims = dims, c->grad = grad, c->f2 = f2, c->basis = b;
    snprintf(c->name, sizeof c->name, fmt, dims, grad ? "+grad" : "", f2 ? "+F2" : "");
    return c;
}

/* timed variants */
typedef struct {
    const char* name;
    int kind, dims, oct, random;
    ak_noise_basis basis;
    double t[2][MAXR];
    int grad;
} timed;

static float* TX[2][3];
static volatile float sink;

static void run_timed(int side, const ak_noise* n, const timed* v) {
    const float *x = TX[v->random][0], *y = TX[v->random][1], *z = TX[v->random][2];
    float s = 0.0f;
    ncase c = {.kind = v->oct > 1 ? K_FRACTAL : v->kind, .dims = v->dims, .basis = v->basis, .grad = v->grad};
    c.fd = (ak_fractal_desc){.type = AK_FRACTAL_FBM, .basis = v->basis, .octaves = (uint32_t)v->oct, .lacunarity = 2,
                             .gain = 0.5f, .frequency = 1};
    if (c.kind == K_PERLIN && v->dims == 3 && !v->grad) {
        if (side == 0)
            for (int i = 0; i < TN; ++i) s += old_ak_noise_perlin3(n, x[i], y[i], z[i], NULL);
        else
            for (int i = 0; i < TN; ++i) s += new_ak_noise_perlin3(n, x[i], y[i], z[i], NULL);
    } else if (c.kind == K_SIMPLEX && v->dims == 3 && !v->grad) {
        if (side == 0)
            for (int i = 0; i < TN; ++i) s += old_ak_noise_simplex3(n, x[i], y[i], z[i], NULL);
        else
            for (int i = 0; i < TN; ++i) s += new_ak_noise_simplex3(n, x[i], y[i], z[i], NULL);
    } else {
        float out[6];
        for (int i = 0; i < TN; ++i) {
            const float p[3] = {x[i], y[i], z[i]};
            eval(side, n, &c, p, out);
            s += out[0];
        }
    }
    sink += s;
}

int main(int argc, char** argv) {
    int R = argc > 1 ? atoi(argv[1]) : 7;
    if (R < 1 || R > MAXR) R = 7;
    const long check = argc > 2 ? atol(argv[2]) : 2000000;
    static const char* bname[4] = {"perlin", "simplex", "value", "worley"};
    static const ak_noise_basis bases[4] = {AK_NOISE_BASIS_PERLIN, AK_NOISE_BASIS_SIMPLEX, AK_NOISE_BASIS_VALUE,
                                            AK_NOISE_BASIS_WORLEY};
    for (int g = 0; g < 2; ++g) {
        for (int d = 1; d <= 4; ++d) add(K_PERLIN, d, g, 0, 0, "perlin%d%s%s");
        for (int d = 1; d <= 4; ++d) add(K_PERIODIC, d, g, 0, 0, "perlin_periodic%d%s%s");
        for (int d = 2; d <= 3; ++d) add(K_SIMPLEX, d, g, 0, 0, "simplex%d%s%s");
        for (int d = 1; d <= 4; ++d) add(K_VALUE, d, g, 0, 0, "value%d%s%s");
        for (int d = 1; d <= 3; ++d)
            for (int f2 = 0; f2 < 2; ++f2) add(K_WORLEY, d, g, f2, 0, "worley%d%s%s");
        for (int b = 0; b < 4; ++b)
            for (int d = 1; d <= 4; ++d) {
                char fmt[64];
                snprintf(fmt, sizeof fmt, "eval-%s%%d%%s%%s", bname[b]);
                add(K_EVAL, d, g, 0, bases[b], fmt);
            }
        for (int t = 0; t < 3; ++t)
            for (int b = 0; b < 4; ++b)
                for (int d = 1; d <= 3; ++d) {
                    char fmt[64];
                    snprintf(fmt, sizeof fmt, "%s5-%s%%d%%s%%s", t == 0 ? "fbm" : t == 1 ? "turb" : "ridged", bname[b]);
                    ncase* c = add(K_FRACTAL, d, g, 0, bases[b], fmt);
                    c->fd = (ak_fractal_desc){.type = (ak_fractal_type)(t + 1), .basis = bases[b], .octaves = 5,
                                              .lacunarity = t == 2 ? 2.1f : 2.0f, .gain = 0.5f, .frequency = t == 1 ? 0.7f : 1.0f};
                }
        ncase* c = add(K_FRACTAL, 3, g, 0, 0, "fbm-default-desc%d%s%s");
        c->fd = (ak_fractal_desc){0};
        c = add(K_FRACTAL, 2, g, 0, 0, "fbm3-perlin-warp%d%s%s");
        c->fd = (ak_fractal_desc){.type = AK_FRACTAL_FBM, .octaves = 3, .warp = 0.8f};
        c = add(K_FRACTAL, 3, g, 0, 0, "fbm1-value%d%s%s");
        c->fd = (ak_fractal_desc){.type = AK_FRACTAL_FBM, .basis = AK_NOISE_BASIS_VALUE, .octaves = 1};
    }
    const uint64_t seeds[3] = {0, 1, 0xDEADBEEF12345ull};
    ak_noise on[3], nn[3];
    for (int s = 0; s < 3; ++s) {
        on[s] = old_ak_noise_make(seeds[s]);
        nn[s] = new_ak_noise_make(seeds[s]);
        if (memcmp(&on[s], &nn[s], sizeof on[s]) != 0) printf("ak_noise_make(%llu) differs\n", (unsigned long long)seeds[s]);
    }
    long total = 0, bad_total = 0;
    printf("bit check: %d cases, %ld points each (fractals %ld), seeds 0, 1, 0xDEADBEEF12345 in turn\n", ncases, check,
           check / 4);
    for (int ci = 0; ci < ncases; ++ci) {
        const ncase* c = &cases[ci];
        const long npts = c->kind == K_FRACTAL ? check / 4 : check;
        long bad = 0;
        for (long i = 0; i < npts; ++i) {
            const float p[4] = {coord(), coord(), coord(), coord()};
            const int s = (int)(i % 3);
            float a[6], b[6];
            eval(0, &on[s], c, p, a);
            eval(1, &nn[s], c, p, b);
            if (memcmp(a, b, sizeof a) != 0) {
                if (bad < 3)
                    printf("  DIFF %s seed %d p (%a %a %a %a): old %a [%a %a %a] new %a [%a %a %a]\n", c->name, s, p[0],
                           p[1], p[2], p[3], a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]);
                ++bad;
            }
        }
        total += npts;
        bad_total += bad;
        if (bad) printf("  %-28s %ld of %ld differ\n", c->name, bad, npts);
    }
    printf("bit check: %ld evaluations per side, %ld differ\n\n", total, bad_total);

    /* timing */
    for (int s = 0; s < 2; ++s)
        for (int k = 0; k < 3; ++k) TX[s][k] = malloc(sizeof(float) * TN);
    for (int k = 0, i = 0; k < 64; ++k)
        for (int j = 0; j < 128; ++j)
            for (int l = 0; l < 128; ++l, ++i)
                TX[0][0][i] = 0.05f + 0.173f * (float)l, TX[0][1][i] = 0.11f + 0.173f * (float)j,
                TX[0][2][i] = 0.07f + 0.173f * (float)k;
    for (int i = 0; i < TN; ++i)
        for (int k = 0; k < 3; ++k) TX[1][k][i] = uni(-100.0f, 100.0f);
    timed tv[] = {
        {"perlin3", K_PERLIN, 3, 1, 0, AK_NOISE_BASIS_PERLIN, {{0}}},
        {"simplex3", K_SIMPLEX, 3, 1, 0, AK_NOISE_BASIS_SIMPLEX, {{0}}},
        {"value3", K_VALUE, 3, 1, 0, AK_NOISE_BASIS_VALUE, {{0}}},
        {"worley3 F1", K_WORLEY, 3, 1, 0, AK_NOISE_BASIS_WORLEY, {{0}}},
        {"perlin2", K_PERLIN, 2, 1, 0, AK_NOISE_BASIS_PERLIN, {{0}}},
        {"simplex2", K_SIMPLEX, 2, 1, 0, AK_NOISE_BASIS_SIMPLEX, {{0}}},
        {"value2", K_VALUE, 2, 1, 0, AK_NOISE_BASIS_VALUE, {{0}}},
        {"worley2 F1", K_WORLEY, 2, 1, 0, AK_NOISE_BASIS_WORLEY, {{0}}},
        {"fbm5 perlin3", K_FRACTAL, 3, 5, 0, AK_NOISE_BASIS_PERLIN, {{0}}},
        {"fbm5 simplex3", K_FRACTAL, 3, 5, 0, AK_NOISE_BASIS_SIMPLEX, {{0}}},
        {"fbm5 value3", K_FRACTAL, 3, 5, 0, AK_NOISE_BASIS_VALUE, {{0}}},
        {"fbm5 worley3", K_FRACTAL, 3, 5, 0, AK_NOISE_BASIS_WORLEY, {{0}}},
        {"perlin3 random", K_PERLIN, 3, 1, 1, AK_NOISE_BASIS_PERLIN, {{0}}},
        {"simplex3 random", K_SIMPLEX, 3, 1, 1, AK_NOISE_BASIS_SIMPLEX, {{0}}},
        {"value3 random", K_VALUE, 3, 1, 1, AK_NOISE_BASIS_VALUE, {{0}}},
        {"worley3 F1 random", K_WORLEY, 3, 1, 1, AK_NOISE_BASIS_WORLEY, {{0}}},
        {"perlin3+grad", K_PERLIN, 3, 1, 0, AK_NOISE_BASIS_PERLIN, {{0}}, 1},
        {"perlin2+grad", K_PERLIN, 2, 1, 0, AK_NOISE_BASIS_PERLIN, {{0}}, 1},
        {"fbm8 perlin2+grad", K_FRACTAL, 2, 8, 0, AK_NOISE_BASIS_PERLIN, {{0}}, 1},
    };
    const int nt = (int)(sizeof tv / sizeof tv[0]);
    const ak_noise* tn[2] = {&on[1], &nn[1]};
    for (int v = 0; v < nt; ++v)
        for (int s = 0; s < 2; ++s) run_timed(s, tn[s], &tv[v]); /* warm-up */
    for (int r = 0; r < R; ++r)
        for (int v = 0; v < nt; ++v)
            for (int k = 0; k < 2; ++k) {
                const int s = (r + v) & 1 ? 1 - k : k;
                const double t0 = cpu_s();
                run_timed(s, tn[s], &tv[v]);
                tv[v].t[s][r] = cpu_s() - t0;
            }
    printf("timing: %d points per pass (lattice 0.173 spacing as noise_bench, or uniform in [-100, 100]^3), %d rounds,\n"
           "old/new interleaved (order alternating), thread CPU time; ns/point median [min-max], new/old median of\n"
           "per-round ratios [min-max]\n",
           TN, R);
    for (int v = 0; v < nt; ++v) {
        double a[MAXR], b[MAXR], q[MAXR], lo, hi, lo2, hi2, lo3, hi3;
        for (int r = 0; r < R; ++r) a[r] = tv[v].t[0][r], b[r] = tv[v].t[1][r], q[r] = b[r] / a[r];
        const double mo = med(a, R, &lo, &hi), mn = med(b, R, &lo2, &hi2), mq = med(q, R, &lo3, &hi3);
        printf("  %-20s old %7.2f [%6.2f-%6.2f]  new %7.2f [%6.2f-%6.2f]  new/old %.3f [%.3f-%.3f]\n", tv[v].name,
               1e9 * mo / TN, 1e9 * lo / TN, 1e9 * hi / TN, 1e9 * mn / TN, 1e9 * lo2 / TN, 1e9 * hi2 / TN, mq, lo3, hi3);
    }
    return bad_total != 0;
}
