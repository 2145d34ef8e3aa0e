/* libFuzzer harness for the glTF/GLB reader (not built by default).
 *
 * Build and run from the repository root (clang 14+; compiles just the modules io needs):
 *     SRCS=$(for m in core math curve clip skeleton mesh scene io; do ls src/$m.c src/$m/[a-z]*.c 2>/dev/null; done)
 *     clang -g -O1 -fsanitize=fuzzer,address,undefined -std=c11 -D_POSIX_C_SOURCE=200809L \
 *         -Iinclude -Isrc tests/fuzz/fuzz_gltf.c $SRCS -lassimp -lcjson -lm -o fuzz_gltf
 *     mkdir -p corpus && cp ../shared/assets/gltf/SimpleSkin/glTF-Embedded/SimpleSkin.gltf \
 *         ../shared/assets/gltf/AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb corpus/
 *     ./fuzz_gltf -max_len=65536 -max_total_time=600 corpus
 *
 * Each input is loaded from memory twice: as given, and with max_influences 1 and animations
 * skipped; a loaded scene is checked with ak_mesh_validate, then destroyed. Any crash, leak
 * or sanitizer report is a bug. */
#include <animkit/io.h>
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_io_desc descs[2] = {{0}, {.max_influences = 1, .skip_animations = true}};
    for (int i = 0; i < 2; ++i) {
        ak_scene* scene = NULL;
        ak_diag diag;
        if (ak_io_load_memory(data, size, "fuzz.gltf", NULL, &descs[i], NULL, &scene, &diag) == AK_OK) {
            for (size_t m = 0; m < scene->mesh_count; ++m)
                if (ak_mesh_validate(scene->meshes[m].mesh, NULL) != AK_OK) abort();
        }
        ak_scene_destroy(scene);
    }
    return 0;
}
