/* libFuzzer target for animkit's BVH reader (src/io/bvh.c); built and run by scripts/fuzz.sh.
 *
 * Each input is loaded from memory as BVH with the default budget and with a 1 MiB budget and
 * animations skipped. A loaded scene must have a finite rest pose and clip duration, and
 * sampling its clip at three times must give finite transforms. Its skeleton also goes through
 * the automatic humanoid mapping (ak_humanoid_roles_find, ak_retarget_map_by_roles onto
 * itself, ak_retarget_map_write): documented codes only, roles on joints of the skeleton,
 * confidences in [0, 1], a humanoid mapped onto itself joint for joint. */
#include <animkit/io.h>
#include <animkit/retarget.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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
    if (!s->skeleton) return;
    ak_humanoid_roles r;
    ak_result rr = ak_humanoid_roles_find(s->skeleton, NULL, &r, NULL);
    if (rr != AK_OK && rr != AK_ERR_NOT_FOUND && rr != AK_ERR_BAD_DATA) abort();
    if (rr == AK_ERR_BAD_DATA) return;
    if ((rr == AK_OK) != r.is_humanoid || !(r.score >= 0.0f && r.score <= 1.0f)) abort();
    size_t nj = ak_skeleton_joint_count(s->skeleton);
    for (int b = 1; b < AK_BONE_COUNT; ++b)
        if (r.joint[b] < -1 || r.joint[b] >= (int32_t)nj || !(r.confidence[b] >= 0.0f && r.confidence[b] <= 1.0f)) abort();
    int32_t* map = (int32_t*)malloc((nj ? nj : 1) * sizeof *map);
    if (!map) abort();
    if (ak_retarget_map_by_roles(s->skeleton, &r, s->skeleton, &r, (ak_i32_span){map, nj}, NULL) != AK_OK) abort();
    for (size_t j = 0; j < nj; ++j)
        if (map[j] != -1 && map[j] != (int32_t)j) abort();
    size_t need = 0;
    if (ak_retarget_map_write(s->skeleton, &r, s->skeleton, &r, (ak_i32_cspan){map, nj}, NULL, 0, &need) != AK_OK) abort();
    char* text = (char*)malloc(need + 1);
    if (!text) abort();
    size_t got = 0;
    if (ak_retarget_map_write(s->skeleton, &r, s->skeleton, &r, (ak_i32_cspan){map, nj}, text, need + 1, &got) != AK_OK ||
        got != need || strlen(text) != need)
        abort();
    free(text);
    free(map);
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
