/* Clip sampling throughput: a 64-joint clip (translation, rotation, scale per joint) with
 * 30 keys per second over 10 s, sampled sequentially (60 Hz playback, looping) and at random
 * times, with a cursor and its key cache (ak_clip_cursor_storage_count elements), a cursor
 * with segments only (ak_clip_channel_count elements) and the per-channel binary search
 * (cursor = NULL), interleaved in the same run. Fixed seeds. Prints joints sampled per
 * second and the ratios. */
#include <animkit/clip.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_clock.h"

enum { JOINTS = 64, KEYS = 301, FRAMES = 4096 };

static ak_clip* make_clip(ak_interp interp, ak_rng* rng) {
    size_t per_key = interp == AK_INTERP_CUBICSPLINE ? 3 : 1;
    float* times = malloc(KEYS * sizeof(float));
    float* tv = malloc((size_t)JOINTS * KEYS * 3 * per_key * sizeof(float));
    float* rv = malloc((size_t)JOINTS * KEYS * 4 * per_key * sizeof(float));
    float* sv = malloc((size_t)JOINTS * KEYS * 3 * per_key * sizeof(float));
    ak_raw_channel* ch = calloc(3 * JOINTS, sizeof(ak_raw_channel));
    if (!times || !tv || !rv || !sv || !ch) return NULL;
    for (int k = 0; k < KEYS; ++k) times[k] = (float)k / 30.0f;
    for (size_t i = 0; i < (size_t)JOINTS * KEYS * 3 * per_key; ++i) {
        tv[i] = ak_rng_range(rng, -1, 1);
        sv[i] = ak_rng_range(rng, 0.9f, 1.1f);
    }
    for (size_t i = 0; i < (size_t)JOINTS * KEYS * per_key; ++i) {
        ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(ak_rng_range(rng, -1, 1), 1, 0), ak_rng_range(rng, -1, 1));
        memcpy(rv + 4 * i, &q, sizeof q);
    }
    for (int j = 0; j < JOINTS; ++j) {
        size_t o3 = (size_t)j * KEYS * 3 * per_key, o4 = (size_t)j * KEYS * 4 * per_key;
        ch[3 * j] = (ak_raw_channel){.target = AK_CHANNEL_TRANSLATION, .index = (uint32_t)j, .interp = interp,
                                     .key_count = KEYS, .times = times, .values = tv + o3};
        ch[3 * j + 1] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION, .index = (uint32_t)j, .interp = interp,
                                         .key_count = KEYS, .times = times, .values = rv + o4};
        ch[3 * j + 2] = (ak_raw_channel){.target = AK_CHANNEL_SCALE, .index = (uint32_t)j, .interp = interp,
                                         .key_count = KEYS, .times = times, .values = sv + o3};
    }
    ak_raw_clip raw = {.name = "bench", .channels = ch, .channel_count = 3 * JOINTS, .joint_count = JOINTS};
    ak_clip* clip = NULL;
    ak_result r = ak_clip_build(&raw, NULL, &clip, NULL);
    free(times), free(tv), free(rv), free(sv), free(ch);
    return r == AK_OK ? clip : NULL;
}

/* One timed pass of FRAMES samples; mode 0 key cache, 1 segments-only cursor, 2 binary
 * search. Returns seconds. */
static double run_once(const ak_clip* clip, const float* times, int mode, float* checksum) {
    ak_transform pose[JOINTS];
    size_t n = mode == 0 ? ak_clip_cursor_storage_count(clip) : ak_clip_channel_count(clip);
    uint32_t* seg = calloc(n, sizeof *seg);
    ak_clip_cursor cursor;
    ak_clip_cursor_init(&cursor, clip, (ak_u32_span){seg, n});
    for (int j = 0; j < JOINTS; ++j) pose[j] = ak_transform_identity();
    double t0 = bench_cpu_s();
    for (int f = 0; f < FRAMES; ++f)
        ak_clip_sample(clip, times[f], mode < 2 ? &cursor : NULL, (ak_transform_span)AK_SPAN(pose), (ak_f32_span){0},
                       (ak_f32_span){0});
    double dt = bench_cpu_s() - t0;
    *checksum += pose[JOINTS / 2].translation.x;
    free(seg);
    return dt;
}

/* The three modes alternate, best of REPS each, so all see the same machine load. Writes
 * joints per second. */
static void run_modes(const ak_clip* clip, const float* times, float* checksum, double jps[3]) {
    enum { REPS = 11 };
    double best[3] = {1e30, 1e30, 1e30};
    for (int rep = 0; rep < REPS; ++rep)
        for (int m = 0; m < 3; ++m) {
            double d = run_once(clip, times, m, checksum);
            best[m] = d < best[m] ? d : best[m];
        }
    for (int m = 0; m < 3; ++m) jps[m] = (double)FRAMES * JOINTS / best[m];
}

int main(void) {
    ak_rng rng = ak_rng_make(2024);
    static float seq[FRAMES], rnd[FRAMES];
    for (int f = 0; f < FRAMES; ++f) {
        seq[f] = ak_time_wrap((float)f / 60.0f, 10.0f, AK_WRAP_LOOP);
        rnd[f] = ak_rng_range(&rng, 0.0f, 10.0f);
    }
    printf("bench_clip: %d joints (T, R, S channels), %d keys per channel (30 keys/s over 10 s), %d samples\n",
           JOINTS, KEYS, FRAMES);
    printf("%-12s %-10s %14s %14s %14s %11s %11s\n", "interp", "access", "cache j/s", "segments j/s", "bsearch j/s",
           "cache/bs", "segments/bs");
    const ak_interp modes[2] = {AK_INTERP_LINEAR, AK_INTERP_CUBICSPLINE};
    float checksum = 0.0f;
    for (int m = 0; m < 2; ++m) {
        ak_clip* clip = make_clip(modes[m], &rng);
        if (!clip) {
            fprintf(stderr, "clip build failed\n");
            return 1;
        }
        const float* sets[2] = {seq, rnd};
        const char* names[2] = {"sequential", "random"};
        for (int s = 0; s < 2; ++s) {
            double j[3];
            run_modes(clip, sets[s], &checksum, j);
            printf("%-12s %-10s %14.3e %14.3e %14.3e %11.2f %11.2f\n", ak_interp_name(modes[m]), names[s], j[0], j[1],
                   j[2], j[0] / j[2], j[1] / j[2]);
        }
        if (modes[m] == AK_INTERP_LINEAR) {
            /* the key cache with each sampling kernel this CPU has (ak_clip_set_simd_limit),
             * interleaved rep by rep, sequential access */
            double best[AK_CLIP_SIMD_COUNT];
            char name[AK_CLIP_SIMD_COUNT][16];
            for (int k = 0; k < AK_CLIP_SIMD_COUNT; ++k) best[k] = 1e30;
            for (int rep = 0; rep < 11; ++rep)
                for (int k = AK_CLIP_SIMD_SSE2; k < AK_CLIP_SIMD_COUNT; ++k) {
                    ak_clip_set_simd_limit(clip, (ak_clip_simd)k);
                    snprintf(name[k], sizeof name[k], "%s", ak_clip_simd_name(clip));
                    double d = run_once(clip, seq, 0, &checksum);
                    best[k] = d < best[k] ? d : best[k];
                }
            ak_clip_set_simd_limit(clip, AK_CLIP_SIMD_DEFAULT);
            for (int k = AK_CLIP_SIMD_SSE2; k < AK_CLIP_SIMD_COUNT; ++k)
                printf("  key cache, linear, sequential, kernel limit %d: %-7s %12.3e j/s  time vs sse2 %.2f\n", k,
                       name[k], (double)FRAMES * JOINTS / best[k], best[k] / best[AK_CLIP_SIMD_SSE2]);
        }
        ak_clip_destroy(clip);
    }
    printf("(checksum %g)\n", (double)checksum);
    return 0;
}
