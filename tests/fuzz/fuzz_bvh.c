/* libFuzzer target for animkit's BVH reader (src/io/bvh.c); built and run by scripts/fuzz.sh.
 *
 * Each input is loaded from memory as BVH with the default budget and with a 1 MiB budget and
 * animations skipped. A loaded scene must have a finite rest pose and clip duration, and
 * sampling its clip at three times must give finite transforms. */
#include <animkit/io.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static void check(const ak_scene* s) {
    size_t n = ak_scene_joint_count(s);
    ak_transform* pose = (ak_transform*)malloc((n ? n : 1) * sizeof *pose);
    if (!pose) abort();
    for (size_t c = 0; c < s->clip_count; ++c) {
        float d = ak_clip_duration(s->clips[c]);
        if (!isfinite(d) || d < 0.0f) abort();
        for (int k = 0; k < 3; ++k) {
            ak_scene_rest_pose(s, (ak_transform_span){pose, n});
            ak_clip_sample(s->clips[c], d * (float)k / 2.0f, NULL, (ak_transform_span){pose, n},
                           (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0});
            for (size_t j = 0; j < n; ++j)
                if (!ak_vec3_is_finite(pose[j].translation) || !isfinite(pose[j].rotation.w)) abort();
        }
    }
    free(pose);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_io_desc descs[2] = {{.format = AK_IO_FORMAT_BVH},
                           {.format = AK_IO_FORMAT_BVH, .skip_animations = true, .memory_budget = 1u << 20}};
    for (int i = 0; i < 2; ++i) {
        ak_scene* scene = NULL;
        ak_diag diag;
        if (ak_io_load_memory(data, size, "fuzz.bvh", NULL, &descs[i], NULL, &scene, &diag) == AK_OK) check(scene);
        ak_scene_destroy(scene);
    }
    return 0;
}
