/* Retargeting and glTF writing rates: CMU 01_01.bvh (long capture) onto builtin:humanoid with
 * and without the foot-contact clean-up (frames per second, and their ratio), then the
 * retargeted character written as .glb and as .gltf + .bin (MB/s, and their ratio).
 * Usage: bench_retarget [REPEATS] (default 5); medians of CPU time. Needs ANIMKIT_ASSETS or
 * ../shared/assets. */
#include <animkit/animkit.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "bench_clock.h"

static double median(double* v, size_t n) { return bench_percentile(v, n, 0.5); }

int main(int argc, char** argv) {
    int reps = argc > 1 ? atoi(argv[1]) : 5;
    if (reps < 1 || reps > 1000) reps = 5;
    char path[1024];
    const char* env = getenv("ANIMKIT_ASSETS");
    snprintf(path, sizeof path, "%s/bvh/01_01.bvh", env && *env ? env : AK_SOURCE_DIR "/../shared/assets");
    ak_scene *src = NULL, *dst = NULL;
    ak_diag diag;
    if (ak_io_load(path, NULL, NULL, &src, &diag) != AK_OK || !src->clip_count) {
        fprintf(stderr, "%s: %s\n", path, diag.message);
        return 1;
    }
    if (ak_builtin_create("humanoid", NULL, NULL, &dst) != AK_OK) return 1;
    double t[2][1000];
    ak_retarget_stats st = {0};
    ak_clip* clip = NULL;
    for (int r = 0; r < reps; ++r)
        for (int clean = 0; clean < 2; ++clean) {
            ak_retarget_desc d = {.source = src->skeleton, .clip = src->clips[0], .target = dst->skeleton,
                                  .skip_foot_contacts = !clean};
            ak_clip* c = NULL;
            double t0 = bench_cpu_s();
            if (ak_retarget_clip(&d, NULL, &c, &st, &diag) != AK_OK) {
                fprintf(stderr, "retarget: %s\n", diag.message);
                return 1;
            }
            t[clean][r] = bench_cpu_s() - t0;
            if (clean && !clip) clip = c;
            else ak_clip_destroy(c);
        }
    double plain = median(t[0], (size_t)reps), feet = median(t[1], (size_t)reps);
    printf("retarget 01_01.bvh -> builtin:humanoid: %zu frames, %zu joints\n", st.frame_count, st.mapped_count);
    printf("  without foot clean-up: %8.0f frames/s (%.2f ms)\n", (double)st.frame_count / plain, 1e3 * plain);
    printf("  with foot clean-up:    %8.0f frames/s (%.2f ms), %zu foot frames pinned\n",
           (double)st.frame_count / feet, 1e3 * feet, st.pinned_frames);
    printf("  ratio clean-up / plain time: %.2f\n", feet / plain);

    ak_scene view = *dst;
    view.clips = &clip;
    view.clip_count = 1;
    const char* outs[2] = {"/tmp/bench_retarget.glb", "/tmp/bench_retarget.gltf"};
    double w[2][1000], bytes[2] = {0, 0};
    for (int r = 0; r < reps; ++r)
        for (int k = 0; k < 2; ++k) {
            double t0 = bench_cpu_s();
            if (ak_io_save(outs[k], &view, NULL, &diag) != AK_OK) {
                fprintf(stderr, "%s: %s\n", diag.path, diag.message);
                return 1;
            }
            w[k][r] = bench_cpu_s() - t0;
        }
    struct stat sb;
    if (stat(outs[0], &sb) == 0) bytes[0] = (double)sb.st_size;
    if (stat(outs[1], &sb) == 0) bytes[1] = (double)sb.st_size;
    if (stat("/tmp/bench_retarget.bin", &sb) == 0) bytes[1] += (double)sb.st_size;
    double g = median(w[0], (size_t)reps), j = median(w[1], (size_t)reps);
    printf("ak_io_save (humanoid mesh + %zu-frame clip):\n", st.frame_count);
    printf("  .glb:        %6.1f MB/s (%.2f ms, %.2f MB)\n", bytes[0] / g / 1e6, 1e3 * g, bytes[0] / 1e6);
    printf("  .gltf+.bin:  %6.1f MB/s (%.2f ms, %.2f MB)\n", bytes[1] / j / 1e6, 1e3 * j, bytes[1] / 1e6);
    printf("  ratio .gltf / .glb time: %.2f\n", j / g);
    remove(outs[0]);
    remove(outs[1]);
    remove("/tmp/bench_retarget.bin");
    ak_clip_destroy(clip);
    ak_scene_destroy(src);
    ak_scene_destroy(dst);
    return 0;
}
