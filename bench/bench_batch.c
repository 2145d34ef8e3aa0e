/* animkit batch: what a job costs beyond its work. Side by side in one run: a job that runs
 * (a small fluid bake, or a BVH retarget onto builtin:humanoid when the shared assets are
 * there) against the same job skipped as up to date (parse, hash the inputs, read the record),
 * and FNV-1a 64 hashing throughput. Prints the medians and the skip / run ratio.
 *     build/bench/bench_batch [REPEATS]     (default 15) */
#include <animkit/animkit.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bench_clock.h"

static ak_batch_row row;

static void measure(const char* what, const char* line, int reps) {
    double* ran = malloc((size_t)reps * sizeof *ran);
    double* skip = malloc((size_t)reps * sizeof *skip);
    if (!ran || !skip) exit(1);
    ak_batch_desc force = {.name = "bench", .output_dir = "bench_batch_out", .force = true};
    ak_batch_desc plain = {.name = "bench", .output_dir = "bench_batch_out"};
    for (int k = 0; k < reps; ++k) {
        double t0 = bench_wall_s();
        if (ak_batch_run_job(line, strlen(line), &force, &row) != AK_OK || row.status != AK_BATCH_RAN) {
            fprintf(stderr, "bench_batch: %s: %s\n", what, row.error);
            exit(1);
        }
        double t1 = bench_wall_s();
        ak_batch_run_job(line, strlen(line), &plain, &row);
        double t2 = bench_wall_s();
        if (row.status != AK_BATCH_SKIPPED) {
            fprintf(stderr, "bench_batch: %s: the re-run did not skip\n", what);
            exit(1);
        }
        ran[k] = t1 - t0, skip[k] = t2 - t1;
    }
    const double r = bench_percentile(ran, (size_t)reps, 0.5), s = bench_percentile(skip, (size_t)reps, 0.5);
    printf("%-34s run %9.3f ms   skip %8.3f ms   skip/run %.4f\n", what, r * 1e3, s * 1e3, s / r);
    free(ran), free(skip);
}

int main(int argc, char** argv) {
    const int reps = argc > 1 ? atoi(argv[1]) : 15;
    if (reps < 1) return 2;
    printf("animkit %s, %d repeats, medians (wall)\n", ak_version_string(), reps);
    measure("bake (dam preset, 500 p., 20 steps)",
            "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:dam\"}, \"parameters\": {\"sim\": \"fluid\","
            " \"steps\": 20, \"count\": 500}, \"output\": \"dam.glb\"}",
            reps);
    char bvh[1200];
    snprintf(bvh, sizeof bvh, "%s/../shared/assets/bvh/02_01.bvh", AK_SOURCE_DIR);
    const char* env = getenv("ANIMKIT_ASSETS");
    if (env) snprintf(bvh, sizeof bvh, "%s/bvh/02_01.bvh", env);
    struct stat st;
    if (stat(bvh, &st) == 0) {
        char line[1600];
        snprintf(line, sizeof line,
                 "{\"kind\": \"retarget\", \"inputs\": {\"source\": \"%s\", \"target\": \"builtin:humanoid\"},"
                 " \"output\": \"walk.glb\"}",
                 bvh);
        measure("retarget (02_01.bvh -> humanoid)", line, reps > 5 ? 5 : reps);
    } else {
        printf("retarget: %s absent (set ANIMKIT_ASSETS)\n", bvh);
    }
    /* hashing: 64 MiB through FNV-1a */
    const size_t n = (size_t)64 << 20;
    unsigned char* buf = malloc(n);
    if (!buf) return 1;
    for (size_t i = 0; i < n; ++i) buf[i] = (unsigned char)(i * 131u);
    double best = 1e9;
    uint64_t h = 0;
    for (int k = 0; k < 3; ++k) {
        double t0 = bench_wall_s();
        h ^= ak_batch_hash_bytes(AK_BATCH_FNV_BASIS, buf, n);
        double t = bench_wall_s() - t0;
        if (t < best) best = t;
    }
    printf("FNV-1a 64 hashing                  %.0f MB/s (checksum %016llx)\n", (double)n / best / 1e6,
           (unsigned long long)h);
    free(buf);
    return 0;
}
