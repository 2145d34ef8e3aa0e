/* bench_skin: skinning throughput and precomputation times, with the memory bandwidth of the
 * same machine measured in the same run (a STREAM-like triad), so the ratios carry over.
 *
 *   build/bench/bench_skin [vertex_count]      (default 1,000,000 vertices, 64 joints, 4 influences)
 *
 * Prints, for LBS (positions; positions + normals), DQS and CoR (positions + normals):
 * M vertices/s and effective GB/s on every kernel this CPU has (AVX-512, AVX2, the library's
 * scalar code, picked with job.simd_limit) and a plain scalar loop written here, single thread
 * in CPU time, all in the same interleaved rounds; 1 vs 2 threads in wall time, interleaved,
 * each against the triad with the same thread count; every kernel on 1..8 influences in
 * cache; the data check; then the CoR precomputation and heat weights on a CesiumMan-sized
 * generated mesh and on CesiumMan itself when the assets and the io module are available.
 * Every ratio printed compares rows measured in the same rounds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pthread.h>
#include <time.h>

#include "bench_clock.h"

#include <animkit/io.h>
#include <animkit/skin.h>

/* $ANIMKIT_ASSETS/rel, else <source>/../shared/assets/rel; NULL when the file is absent. */
static const char* asset_path(char* buf, size_t size, const char* rel) {
    const char* env = getenv("ANIMKIT_ASSETS");
    if (env && *env) snprintf(buf, size, "%s/%s", env, rel);
    else snprintf(buf, size, "%s/../shared/assets/%s", AK_SOURCE_DIR, rel);
    FILE* f = fopen(buf, "rb");
    if (!f) return NULL;
    fclose(f);
    return buf;
}

/* Single-thread figures use this thread's CPU time, so that other processes on a loaded
 * machine do not count (cache and memory contention still do); two-thread figures and the
 * precomputations use wall time (g_use_cpu_time = false). */
static int g_use_cpu_time = 1;
static double now_s(void) { return g_use_cpu_time ? bench_cpu_s() : bench_wall_s(); }

/* ---- STREAM-like triad: a[i] = b[i] + s * c[i] (12 bytes counted per float element) ---- */

/* GB/s of the best of reps passes over n floats (arrays kept between calls, so the triad can
 * also run between the kernel rounds below: a burst of load from elsewhere then cannot make
 * one triad measurement low and every "% of triad" high). */
#define TRIAD_N (16u << 20)
static float *g_ta, *g_tb, *g_tc;
static double g_triad_best = 0.0; /* best GB/s seen in this run */
static double triad_pass_gbps(int reps) {
    const size_t n = TRIAD_N;
    if (!g_ta) {
        g_ta = (float*)malloc(n * sizeof(float));
        g_tb = (float*)malloc(n * sizeof(float));
        g_tc = (float*)malloc(n * sizeof(float));
        if (!g_ta || !g_tb || !g_tc) {
            printf("out of memory\n");
            exit(1);
        }
        for (size_t i = 0; i < n; ++i) {
            g_ta[i] = 0.0f;
            g_tb[i] = (float)(i & 1023);
            g_tc[i] = 1.0f;
        }
    }
    float *a = g_ta, *b = g_tb, *c = g_tc;
    double best = 1e30;
    for (int rep = 0; rep < reps; ++rep) {
        const float s = 1.0f + 1e-3f * (float)rep;
        double t0 = now_s();
        for (size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
        double t = now_s() - t0;
        if (t < best) best = t;
    }
    volatile float sink = a[n / 2];
    (void)sink;
    const double gbs = 12.0 * (double)n / best * 1e-9;
    if (g_use_cpu_time && gbs > g_triad_best) g_triad_best = gbs;
    return gbs;
}
/* The same triad split over two threads (wall time): what memory allows two cores. */
typedef struct triad_part {
    float *a, *b, *c;
    size_t n;
    float s;
} triad_part;
static void* triad_thread(void* arg) {
    triad_part* t = (triad_part*)arg;
    for (size_t i = 0; i < t->n; ++i) t->a[i] = t->b[i] + t->s * t->c[i];
    return NULL;
}
/* One pass of the triad over the same arrays split over two threads, GB/s (wall time). */
static double triad2_pass_gbps(void) {
    const size_t n = TRIAD_N;
    triad_pass_gbps(0); /* allocates the arrays on first use */
    triad_part p0 = {g_ta, g_tb, g_tc, n / 2, 1.0f}, p1 = {g_ta + n / 2, g_tb + n / 2, g_tc + n / 2, n - n / 2, 1.0f};
    double t0 = bench_wall_s();
    pthread_t id;
    bool started = pthread_create(&id, NULL, triad_thread, &p1) == 0;
    triad_thread(&p0);
    if (started) pthread_join(id, NULL);
    else triad_thread(&p1);
    return 12.0 * (double)n / (bench_wall_s() - t0) * 1e-9;
}

/* The kernels this CPU runs, slowest first: scalar, then AVX2 and AVX-512 where present. */
static int bench_levels(ak_skin_simd* out, const char** names) {
    const char* best = ak_skin_simd_name();
    int n = 0;
    out[n] = AK_SKIN_SIMD_SCALAR, names[n++] = "scalar";
    if (!strcmp(best, "avx2") || !strcmp(best, "avx512")) out[n] = AK_SKIN_SIMD_AVX2, names[n++] = "avx2";
    if (!strcmp(best, "avx512")) out[n] = AK_SKIN_SIMD_AVX512, names[n++] = "avx512";
    return n;
}

/* ---- the plain scalar loop: blend four matrices, transform, inverse-transpose normal ---- */

static void plain_lbs(size_t n, const ak_vec3* pos, const ak_vec3* nrm, const uint16_t* jn, const float* w,
                      const ak_mat4* pal, ak_vec3* op, ak_vec3* on) {
    for (size_t i = 0; i < n; ++i) {
        float m[12] = {0};
        for (int k = 0; k < 4; ++k) {
            const float* p = pal[jn[4 * i + k]].m;
            float wk = w[4 * i + k];
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 3; ++r) m[c * 3 + r] += wk * p[c * 4 + r];
        }
        ak_vec3 p = pos[i];
        op[i] = ak_vec3_make(m[0] * p.x + m[3] * p.y + m[6] * p.z + m[9], m[1] * p.x + m[4] * p.y + m[7] * p.z + m[10],
                             m[2] * p.x + m[5] * p.y + m[8] * p.z + m[11]);
        if (on) {
            ak_vec3 c0 = ak_vec3_make(m[0], m[1], m[2]), c1 = ak_vec3_make(m[3], m[4], m[5]), c2 = ak_vec3_make(m[6], m[7], m[8]);
            ak_mat3 it = ak_mat3_transpose(ak_mat3_inverse(ak_mat3_from_cols(c0, c1, c2)));
            on[i] = ak_vec3_normalize(ak_mat3_mul_vec3(it, nrm[i]));
        }
    }
}

typedef struct bench_data {
    size_t n;
    ak_vec3 *pos, *nrm, *ctr, *op, *on;
    uint16_t* jn;
    float* w;
    ak_mat4 pal[64];
    unsigned char scratch[64 + 192 * 64]; /* ak_skin_job_scratch_size for CoR, 64 joints */
} bench_data;

/* The four jobs (LBS positions, LBS positions+normals, DQS, CoR) run in turn, one run each
 * per round, best of the rounds: a burst of load from elsewhere on the machine then slows one
 * round of every job rather than every round of one job, so the ratios between them hold. */
static double time_job(const ak_skin_job* job, int reps);
static const char* const labels[4] = {"LBS positions", "LBS positions+normals", "DQS positions+normals",
                                      "CoR positions+normals"};
static void time_four(ak_skin_job* job, const ak_vec3* normals, int rounds, double* t /* in/out: best so far */) {
    static const ak_skin_method methods[4] = {AK_SKIN_LBS, AK_SKIN_LBS, AK_SKIN_DQS, AK_SKIN_COR};
    const size_t n = job->positions.count;
    for (int round = 0; round < rounds; ++round) {
        triad_pass_gbps(1);
        for (int m = 0; m < 4; ++m) {
            job->method = methods[m];
            job->normals = m == 0 ? (ak_cstream){NULL, 0, 0} : (ak_cstream){normals, n, 0};
            t[m] = fmin(t[m], time_job(job, 1));
        }
    }
    job->normals = (ak_cstream){normals, n, 0};
}

/* Best of reps runs of the job, in seconds. */
static double time_job(const ak_skin_job* job, int reps) {
    double best = 1e30;
    for (int r = 0; r < reps; ++r) {
        double t0 = now_s();
        ak_result res = ak_skin_job_run(job);
        double t = now_s() - t0;
        if (res != AK_OK) {
            printf("job failed: %s\n", ak_result_string(res));
            exit(1);
        }
        if (t < best) best = t;
    }
    return best;
}

static void row(const char* name, double bytes_per_vertex, size_t n, double t, double triad, double plain_t) {
    double mvs = (double)n / t * 1e-6, gbs = bytes_per_vertex * (double)n / t * 1e-9;
    printf("  %-34s %8.1f Mvert/s %6.1f GB/s %5.0f%% of triad", name, mvs, gbs, 100.0 * gbs / triad);
    if (plain_t > 0.0) printf("  x%.2f vs plain loop", plain_t / t);
    printf("\n");
}

/* A capped cylinder of `rings` x `segments` with a chain of `joints` joints along +Y, skinned
 * with inverse-distance weights (4 influences): a stand-in for a character limb mesh. */
static void make_limb(int rings, int segments, int joints, ak_vec3** out_pos, uint32_t** out_idx, size_t* out_n,
                      size_t* out_tris, ak_skin_bone* bones) {
    size_t n = (size_t)rings * segments + 2, tris = (size_t)(rings - 1) * segments * 2 + 2 * (size_t)segments;
    ak_vec3* pos = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    uint32_t* idx = (uint32_t*)malloc(tris * 3 * sizeof(uint32_t));
    const float len = (float)joints * 0.5f;
    ak_rng rng = ak_rng_make(77);
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            /* radius jitter: no two vertices share their weights (no symmetric shortcut) */
            float a = AK_TWO_PI * (float)s / (float)segments, y = len * (float)r / (float)(rings - 1);
            float rad = 0.2f * ak_rng_range(&rng, 0.95f, 1.05f);
            pos[(size_t)r * segments + s] = ak_vec3_make(rad * cosf(a), y, -rad * sinf(a));
        }
    size_t bottom = (size_t)rings * segments;
    pos[bottom] = ak_vec3_make(0, 0, 0);
    pos[bottom + 1] = ak_vec3_make(0, len, 0);
    size_t t = 0;
    for (int r = 0; r + 1 < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            uint32_t a = (uint32_t)(r * segments + s), b = (uint32_t)(r * segments + (s + 1) % segments);
            uint32_t q[6] = {a, b, b + (uint32_t)segments, a, b + (uint32_t)segments, a + (uint32_t)segments};
            memcpy(&idx[3 * t], q, sizeof q);
            t += 2;
        }
    for (int s = 0; s < segments; ++s) {
        uint32_t a = (uint32_t)s, b = (uint32_t)((s + 1) % segments), o = (uint32_t)((rings - 1) * segments);
        uint32_t lo[3] = {(uint32_t)bottom, b, a}, hi[3] = {(uint32_t)bottom + 1, o + a, o + b};
        memcpy(&idx[3 * t++], lo, sizeof lo);
        memcpy(&idx[3 * t++], hi, sizeof hi);
    }
    for (int j = 0; j < joints; ++j) {
        ak_skin_bone b = {{0, 0.5f * (float)j, 0}, {0, 0.5f * (float)(j + 1), 0}, (uint16_t)j};
        bones[j] = b;
    }
    *out_pos = pos;
    *out_idx = idx;
    *out_n = n;
    *out_tris = tris;
}

static void precompute_bench(const char* name, const ak_vec3* pos, size_t n, const uint32_t* idx, size_t tris,
                             const uint16_t* jn, const float* w, uint32_t k) {
    ak_vec3* ctr = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_skin_cor_desc d = {
        .positions = {pos, n},
        .indices = {idx, 3 * tris},
        .joints = {jn, n * k},
        .weights = {w, n * k},
        .influence_count = k,
    };
    double t[3], cpu[3];
    for (int v = 0; v < 3; ++v) {
        d.thread_count = v == 0 ? 2u : 1u;
        d.naive = v == 2;
        struct timespec c0, c1;
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
        double t0 = now_s();
        ak_result r = ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){ctr, n});
        t[v] = now_s() - t0;
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
        cpu[v] = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
        if (r != AK_OK) printf("  CoR precompute failed: %s\n", ak_result_string(r));
    }
    printf("  CoR precompute %s (%zu verts, %zu tris), wall / CPU seconds:\n"
           "      pruned 2 threads %.3f / %.3f, pruned 1 thread %.3f / %.3f, naive 1 thread %.3f / %.3f "
           "(naive/pruned CPU x%.1f)\n",
           name, n, tris, t[0], cpu[0], t[1], cpu[1], t[2], cpu[2], cpu[2] / cpu[1]);
    free(ctr);
}

/* Every kernel on every influence count with the data in cache (4096 vertices, the job
 * repeated 64 times per measurement), single thread, CPU time, interleaved rounds. */
static void in_cache_bench(const bench_data* b, int reps) {
    enum { N = 4096, INNER = 64 };
    static const uint32_t ks[6] = {1, 2, 3, 4, 5, 8};
    static const ak_skin_method methods[4] = {AK_SKIN_LBS, AK_SKIN_LBS, AK_SKIN_DQS, AK_SKIN_COR};
    ak_skin_simd lv[3];
    const char* ln[3];
    const int level_count = bench_levels(lv, ln);
    uint16_t* jn = (uint16_t*)malloc(N * 8 * sizeof(uint16_t));
    float* w = (float*)malloc(N * 8 * sizeof(float));
    ak_vec3 *op = (ak_vec3*)malloc(N * sizeof(ak_vec3)), *on = (ak_vec3*)malloc(N * sizeof(ak_vec3));
    unsigned char* scratch = (unsigned char*)malloc(64 + 192 * 64);
    ak_rng rng = ak_rng_make(99);
    printf("\n  in cache (%d vertices, 64 joints, the job run %d times per measurement; single thread, CPU time,\n"
           "  best of %d rounds, each round runs every job on every kernel once), M vertices/s:\n",
           N, INNER, reps);
    printf("  %-26s", "job");
    for (int l = level_count - 1; l >= 0; --l) printf(" %9s", ln[l]);
    if (level_count > 2) printf("  avx512/avx2");
    if (level_count > 1) printf("  avx2/scalar");
    printf("\n");
    for (int kc = 0; kc < 6; ++kc) {
        const uint32_t K = ks[kc];
        for (size_t i = 0; i < N; ++i) { /* neighbouring vertices share nearby joints */
            const uint32_t base = (uint32_t)((i * 64) / N);
            float rest = 1.0f;
            for (uint32_t k = 0; k < K; ++k) {
                const float wk = k + 1 == K ? rest : rest * (0.3f + 0.5f * ak_rng_float(&rng));
                jn[K * i + k] = (uint16_t)((base + k * 3u + (ak_rng_u32(&rng) & 1u)) % 64u);
                w[K * i + k] = wk;
                rest -= wk;
            }
        }
        ak_skin_job job = {
            .influence_count = K,
            .palette = {b->pal, 64},
            .positions = {b->pos, N, 0},
            .joints = {jn, N, 0},
            .weights = {w, N, 0},
            .cor_centers = {b->ctr, N, 0},
            .out_positions = {op, N, 0},
            .out_normals = {on, N, 0},
            .scratch = {scratch, 64 + 192 * 64},
        };
        if (ak_skin_job_validate(&job) != AK_OK) {
            printf("invalid in-cache data\n");
            exit(1);
        }
        job.skip_data_check = true;
        double t[4][3];
        for (int m = 0; m < 4; ++m)
            for (int l = 0; l < 3; ++l) t[m][l] = 1e30;
        for (int round = 0; round < reps; ++round)
            for (int m = 0; m < 4; ++m) {
                job.method = methods[m];
                job.normals = m == 0 ? (ak_cstream){NULL, 0, 0} : (ak_cstream){b->nrm, N, 0};
                for (int l = 0; l < level_count; ++l) {
                    job.simd_limit = lv[l];
                    double t0 = now_s();
                    for (int r = 0; r < INNER; ++r) ak_skin_job_run(&job);
                    t[m][l] = fmin(t[m][l], now_s() - t0);
                }
            }
        for (int m = 0; m < 4; ++m) {
            char name[64];
            snprintf(name, sizeof name, "%s, %u infl.", labels[m], K);
            printf("  %-26s", name);
            for (int l = level_count - 1; l >= 0; --l) printf(" %9.1f", (double)N * INNER / t[m][l] * 1e-6);
            if (level_count > 2) printf("  x%10.2f", t[m][1] / t[m][2]);
            if (level_count > 1) printf("  x%10.2f", t[m][0] / t[m][1]);
            printf("\n");
        }
    }
    free(jn), free(w), free(op), free(on), free(scratch);
}

int main(int argc, char** argv) {
    size_t n = argc > 1 ? (size_t)strtoull(argv[1], NULL, 10) : 1000000u;
    if (n < 64) n = 64;
    printf("bench_skin: %zu vertices, 64 joints, 4 influences, kernel %s\n", n, ak_skin_simd_name());
    double triad = triad_pass_gbps(6);
    printf("  STREAM-like triad (3 x 64 MiB float arrays): %.1f GB/s\n", triad);

    /* calloc: the palette gets malloc's 16-byte alignment, as a caller's usually does */
    bench_data* b = (bench_data*)calloc(1, sizeof *b);
    if (!b) return 1;
    b->n = n;
    b->pos = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    b->nrm = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    b->ctr = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    b->op = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    b->on = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    b->jn = (uint16_t*)malloc(n * 4 * sizeof(uint16_t));
    b->w = (float*)malloc(n * 4 * sizeof(float));
    ak_rng rng = ak_rng_make(1234);
    for (int j = 0; j < 64; ++j) {
        ak_vec3 axis = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1));
        b->pal[j] = ak_mat4_from_quat(ak_quat_from_axis_angle(axis, ak_rng_range(&rng, -3, 3)));
        b->pal[j].m[12] = ak_rng_range(&rng, -1, 1);
        b->pal[j].m[13] = ak_rng_range(&rng, -1, 1);
        b->pal[j].m[14] = ak_rng_range(&rng, -1, 1);
    }
    for (size_t i = 0; i < n; ++i) {
        b->pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1));
        b->nrm[i] = ak_vec3_normalize(ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), 1.0f));
        b->ctr[i] = ak_vec3_scale(b->pos[i], 0.5f);
        /* neighbouring vertices share nearby joints, as in real meshes */
        uint32_t base = (uint32_t)((i * 64) / n);
        float a = ak_rng_float(&rng), c = ak_rng_float(&rng) * (1.0f - a), d = ak_rng_float(&rng) * (1.0f - a - c);
        float ws[4] = {a, c, d, 1.0f - a - c - d};
        for (int k = 0; k < 4; ++k) {
            b->jn[4 * i + k] = (uint16_t)((base + (uint32_t)k) % 64u);
            b->w[4 * i + k] = ws[k];
        }
    }
    ak_skin_job job = {
        .influence_count = 4,
        .palette = {b->pal, 64},
        .positions = {b->pos, n, 0},
        .joints = {b->jn, n, 0},
        .weights = {b->w, n, 0},
        .cor_centers = {b->ctr, n, 0},
        .out_positions = {b->op, n, 0},
        .out_normals = {b->on, n, 0},
        .scratch = {b->scratch, sizeof b->scratch},
    };
    if (ak_skin_job_validate(&job) != AK_OK) {
        printf("invalid benchmark data\n");
        return 1;
    }
    job.skip_data_check = true; /* checked once above; the per-frame path is O(1) */
    const int reps = bench_quick() ? 1 : 7; /* rounds of 3 * reps; 1 under AK_BENCH_QUICK */
    /* bytes moved per vertex: inputs (pos 12, joints 8, weights 16, normals 12, centers 12) + outputs */
    const double bytes_pos = 12 + 8 + 16 + 12, bytes_pn = bytes_pos + 12 + 12, bytes_cor = bytes_pn + 12;

    /* ---- single thread, every kernel this CPU has, interleaved ---- */
    ak_skin_simd lv[3];
    const char* ln[3];
    const int level_count = bench_levels(lv, ln);
    const double bytes[4] = {bytes_pos, bytes_pn, bytes_pn, bytes_cor};
    double plain_p = 1e30, plain_pn = 1e30;
    double t1[3][4];
    for (int l = 0; l < 3; ++l)
        for (int m = 0; m < 4; ++m) t1[l][m] = 1e30;
    job.thread_count = 1;
    for (int round = 0; round < 3 * reps; ++round) { /* one run of everything per round */
        double t0 = now_s();
        plain_lbs(n, b->pos, NULL, b->jn, b->w, b->pal, b->op, NULL);
        double ta = now_s();
        plain_lbs(n, b->pos, b->nrm, b->jn, b->w, b->pal, b->op, b->on);
        double tb = now_s();
        plain_p = fmin(plain_p, ta - t0);
        plain_pn = fmin(plain_pn, tb - ta);
        for (int l = 0; l < level_count; ++l) {
            job.simd_limit = lv[l];
            time_four(&job, b->nrm, 1, t1[l]);
        }
    }
    job.simd_limit = AK_SKIN_SIMD_DEFAULT;
    triad = g_triad_best;
    printf("\n  single thread (CPU time), best of %d rounds; each round runs the triad, the plain loops and every\n"
           "  job on every kernel once (triad: best of the run, %.1f GB/s):\n",
           3 * reps, triad);
    row("plain scalar loop, positions", bytes_pos, n, plain_p, triad, 0);
    row("plain scalar loop, positions+normals", bytes_pn, n, plain_pn, triad, 0);
    for (int m = 0; m < 4; ++m) {
        for (int l = level_count - 1; l >= 0; --l) {
            char name[64];
            snprintf(name, sizeof name, "%s (%s)", labels[m], ln[l]);
            /* the plain loop is LBS: only the LBS rows compare with it */
            row(name, bytes[m], n, t1[l][m], triad, m == 0 ? plain_p : m == 1 ? plain_pn : 0.0);
        }
    }
    printf("  kernel ratios (time of the slower / time of the faster, same rounds):\n");
    for (int m = 0; m < 4; ++m) {
        printf("    %-24s", labels[m]);
        if (level_count > 2) printf(" avx512 vs avx2 x%.2f,", t1[1][m] / t1[2][m]);
        if (level_count > 1) printf(" avx2 vs scalar x%.2f,", t1[0][m] / t1[1][m]);
        printf(" %s vs scalar x%.2f\n", ln[level_count - 1], t1[0][m] / t1[level_count - 1][m]);
    }
    const int best = level_count - 1;
    printf("  ratios (%s, positions+normals): DQS/LBS %.2f, CoR/DQS %.2f\n", ln[best], t1[best][2] / t1[best][1],
           t1[best][3] / t1[best][2]);

    /* ---- 1 vs 2 threads, wall time, interleaved ---- */
    g_use_cpu_time = 0;
    {
        double tw[2][4] = {{1e30, 1e30, 1e30, 1e30}, {1e30, 1e30, 1e30, 1e30}}, tr[2] = {0.0, 0.0};
        static const ak_skin_method methods[4] = {AK_SKIN_LBS, AK_SKIN_LBS, AK_SKIN_DQS, AK_SKIN_COR};
        for (int round = 0; round < 3 * reps; ++round) {
            tr[0] = fmax(tr[0], triad_pass_gbps(1));
            tr[1] = fmax(tr[1], triad2_pass_gbps());
            for (int m = 0; m < 4; ++m) {
                job.method = methods[m];
                job.normals = m == 0 ? (ak_cstream){NULL, 0, 0} : (ak_cstream){b->nrm, n, 0};
                for (int th = 0; th < 2; ++th) { /* alternate which goes first */
                    const int threads = (round + th) % 2 + 1;
                    job.thread_count = (uint32_t)threads;
                    tw[threads - 1][m] = fmin(tw[threads - 1][m], time_job(&job, 1));
                }
            }
        }
        job.normals = (ak_cstream){b->nrm, n, 0};
        printf("\n  1 vs 2 threads (%s, wall time), best of %d rounds; each round runs the 1- and 2-thread triads and\n"
               "  every job on 1 and 2 threads once; %% of the triad with the same thread count\n"
               "  (triad 1 thread %.1f GB/s, 2 threads %.1f GB/s):\n",
               ak_skin_simd_name(), 3 * reps, tr[0], tr[1]);
        for (int th = 0; th < 2; ++th)
            for (int m = 0; m < 4; ++m) {
                char name[64];
                snprintf(name, sizeof name, "%s, %d thread%s", labels[m], th + 1, th ? "s" : "");
                row(name, bytes[m], n, tw[th][m], tr[th], 0);
            }
        printf("  2 threads vs 1 (wall, same rounds): LBS positions x%.2f, LBS positions+normals x%.2f, DQS x%.2f, "
               "CoR x%.2f\n",
               tw[0][0] / tw[1][0], tw[0][1] / tw[1][1], tw[0][2] / tw[1][2], tw[0][3] / tw[1][3]);
        job.thread_count = 1;
    }
    g_use_cpu_time = 1;

    /* ---- every influence count, in cache, every kernel ---- */
    in_cache_bench(b, reps);

    /* ---- the default per-frame data check ---- */
    printf("\n  the data check (job.skip_data_check = false, the default: every weight, joint index, position and\n"
           "  normal is checked before the job writes anything), LBS positions+normals, %s:\n", ak_skin_simd_name());
    {
        job.method = AK_SKIN_LBS;
        job.normals = (ak_cstream){b->nrm, n, 0};
        job.skip_data_check = false;
        g_use_cpu_time = 1;
        double tv = 1e30;
        for (int r = 0; r < 3 * reps; ++r) {
            double t0 = now_s();
            ak_result res = ak_skin_job_validate(&job);
            tv = fmin(tv, now_s() - t0);
            if (res != AK_OK) return 1;
        }
        row("ak_skin_job_validate alone", 48, n, tv, triad, 0);
        for (uint32_t threads = 1; threads <= 2; ++threads) {
            g_use_cpu_time = threads == 1; /* 2 threads: wall time */
            job.thread_count = threads;
            double t_skip = 1e30, t_check = 1e30;
            for (int r = 0; r < 2 * reps; ++r) { /* interleaved */
                job.skip_data_check = true;
                t_skip = fmin(t_skip, time_job(&job, 1));
                job.skip_data_check = false;
                t_check = fmin(t_check, time_job(&job, 1));
            }
            char name[64];
            snprintf(name, sizeof name, "run with the check, %u thread%s", threads, threads > 1 ? "s" : "");
            row(name, bytes_pn, n, t_check, triad, 0);
            printf("  %-34s %8.1f Mvert/s: the check costs %.0f%% (same rounds)\n", "  the same job, check skipped",
                   n / t_skip * 1e-6, 100.0 * (t_check - t_skip) / t_skip);
        }
        job.skip_data_check = true;
        job.thread_count = 1;
        g_use_cpu_time = 1;
    }

    /* ---- precomputation on character-sized meshes ---- */
    printf("\n  precomputation:\n");
    {
        ak_vec3* pos;
        uint32_t* idx;
        size_t vn, tris;
        ak_skin_bone bones[19];
        make_limb(102, 32, 19, &pos, &idx, &vn, &tris, bones); /* 3266 vertices, 19 joints: CesiumMan's size */
        uint16_t* jn = (uint16_t*)malloc(vn * 4 * sizeof(uint16_t));
        float* w = (float*)malloc(vn * 4 * sizeof(float));
        for (int m = 0; m < 2; ++m) {
            ak_weights_desc wd = {
                .method = m == 0 ? AK_WEIGHTS_DISTANCE : AK_WEIGHTS_HEAT,
                .positions = {pos, vn},
                .indices = {idx, 3 * tris},
                .bones = {bones, 19},
            };
            double t0 = now_s();
            ak_result r = ak_skin_weights_compute(&wd, NULL, (ak_u16_span){jn, 4 * vn}, (ak_f32_span){w, 4 * vn});
            printf("  weights %-8s on the generated limb (%zu verts, 19 joints): %.3f s (%s)\n",
                   m == 0 ? "distance" : "heat", vn, now_s() - t0, ak_result_string(r));
        }
        if (bench_quick()) printf("  CoR precompute on the generated limb: skipped (AK_BENCH_QUICK)\n");
        else precompute_bench("generated limb, heat w.", pos, vn, idx, tris, jn, w, 4);
        free(jn);
        free(w);
        free(pos);
        free(idx);
    }
    char path[1024];
    if (asset_path(path, sizeof path, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb")) {
        ak_scene* scene = NULL;
        ak_result r = ak_io_load(path, NULL, NULL, &scene, NULL);
        if (r == AK_OK) {
            for (size_t m = 0; m < scene->mesh_count; ++m) {
                const ak_mesh* mesh = scene->meshes[m].mesh;
                if (!mesh->influence_count || !mesh->triangle_count) continue;
                precompute_bench("CesiumMan.glb", mesh->positions, mesh->vertex_count, mesh->indices,
                                 mesh->triangle_count, mesh->joints, mesh->weights, mesh->influence_count);
            }
            /* The kernels on a real mesh's joint layout: the synthetic data above gives runs of
             * vertices the same four joints; CesiumMan's own joints and weights, repeated over
             * the 1M vertices, have the neighbour structure of a real skinned mesh. */
            const ak_mesh* mesh = NULL;
            for (size_t m = 0; m < scene->mesh_count && !mesh; ++m)
                if (scene->meshes[m].mesh->influence_count == 4) mesh = scene->meshes[m].mesh;
            if (mesh) {
                for (size_t i = 0; i < n; ++i) {
                    const size_t src = i % mesh->vertex_count;
                    for (int k = 0; k < 4; ++k) {
                        b->jn[4 * i + k] = (uint16_t)(mesh->joints[4 * src + k] % 64u);
                        b->w[4 * i + k] = mesh->weights[4 * src + k];
                    }
                }
                job.thread_count = 1;
                job.skip_simd = false;
                g_use_cpu_time = 1;
                double t[4] = {1e30, 1e30, 1e30, 1e30};
                time_four(&job, b->nrm, 3 * reps, t);
                printf("\n  CesiumMan.glb's joints and weights repeated over the %zu vertices (single thread, %s):\n",
                       n, ak_skin_simd_name());
                const double bytes[4] = {bytes_pos, bytes_pn, bytes_pn, bytes_cor};
                printf("  (triad, best of this run: %.1f GB/s)\n", g_triad_best);
                for (int m = 0; m < 4; ++m) row(labels[m], bytes[m], n, t[m], g_triad_best, 0);
                printf("  ratios: DQS/LBS %.2f, CoR/DQS %.2f\n", t[2] / t[1], t[3] / t[2]);
            }
            ak_scene_destroy(scene);
        } else {
            printf("  CesiumMan: not loaded (%s)\n", ak_result_string(r));
        }
    } else {
        printf("  CesiumMan: SKIP (assets not found)\n");
    }
    free(b->pos);
    free(b->nrm);
    free(b->ctr);
    free(b->op);
    free(b->on);
    free(b->jn);
    free(b->w);
    free(b);
    free(g_ta);
    free(g_tb);
    free(g_tc);
    return 0;
}
