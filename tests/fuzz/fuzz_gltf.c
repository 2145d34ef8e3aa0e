/* libFuzzer target for the glTF/GLB reader; built and run by scripts/fuzz.sh (see docs/io.md).
 *
 * Each input is loaded from memory twice: as given, and with max_influences 1, animations
 * skipped and a 4 MiB memory budget. base_dir is the SimpleSkin folder of the shared assets
 * (its four .bin files are in the dictionary), so external buffers, percent-decoding and the
 * "stay inside the model's folder" check are fuzzed too. A loaded scene is checked with
 * ak_mesh_validate and its skeleton with the automatic humanoid fit (ak_humanoid_roles_find:
 * documented codes only, roles on joints of the skeleton), then destroyed. Any crash, leak or
 * sanitizer report is a bug. */
#include <animkit/io.h>
#include <animkit/retarget.h>
#include <stdint.h>
#include <stdlib.h>

#ifndef AK_FUZZ_ASSETS
#define AK_FUZZ_ASSETS "../shared/assets"
#endif

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const char* base = AK_FUZZ_ASSETS "/gltf/SimpleSkin/glTF";
    ak_io_desc descs[2] = {{.format = AK_IO_FORMAT_GLTF},
                           {.format = AK_IO_FORMAT_GLTF, .max_influences = 1, .skip_animations = true,
                            .memory_budget = 4u << 20}};
    for (int i = 0; i < 2; ++i) {
        ak_scene* scene = NULL;
        ak_diag diag;
        if (ak_io_load_memory(data, size, i ? "fuzz.glb" : "fuzz.gltf", base, &descs[i], NULL, &scene, &diag) == AK_OK) {
            for (size_t m = 0; m < scene->mesh_count; ++m)
                if (ak_mesh_validate(scene->meshes[m].mesh, NULL) != AK_OK) abort();
            ak_humanoid_roles r;
            ak_result rr = scene->skeleton ? ak_humanoid_roles_find(scene->skeleton, NULL, &r, NULL) : AK_ERR_BAD_DATA;
            if (rr != AK_OK && rr != AK_ERR_NOT_FOUND && rr != AK_ERR_BAD_DATA) abort();
            for (int b = 1; rr != AK_ERR_BAD_DATA && b < AK_BONE_COUNT; ++b)
                if (r.joint[b] < -1 || r.joint[b] >= (int32_t)ak_skeleton_joint_count(scene->skeleton)) abort();
        }
        ak_scene_destroy(scene);
    }
    return 0;
}
