/* libFuzzer target for the Assimp path on OBJ input (ak_io_load with AK_IO_FORMAT_ASSIMP -> the
 * Assimp pre-checks -> Assimp's OBJ importer in a forked, rlimited child -> the scene sent back
 * over a pipe -> the parent's checks while rebuilding it); built and run by scripts/fuzz.sh.
 * animkit's own OBJ reader, which AUTO picks for .obj, has its own target (fuzz_obj_mtl).
 *
 * Since Assimp runs in a child process, a crash in it is a reported error (AK_ERR_IO naming the
 * signal), not a finding here: what this target can still find is a bug in animkit's
 * conversion or in the parent's reading of the child's message. (Coverage gathered in the
 * child does not reach libFuzzer, so the corpus grows from the parent's side only.)
 *
 * Assimp reads files only, so each input is written to one temporary .obj file, alone in a
 * private directory (mkdtemp in $TMPDIR or /tmp, removed at exit), and loaded from there: an
 * input's "mtllib" can then name no file but itself, so a run does not depend on what other
 * processes leave in /tmp. Its one known leak on failed imports is suppressed through
 * tests/fuzz/lsan.supp. A loaded scene's meshes must validate. */
#include <animkit/io.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static char g_dir[4096], g_path[4096 + 16];

static void remove_tmp(void) {
    unlink(g_path);
    rmdir(g_dir);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (!g_path[0]) {
        const char* tmp = getenv("TMPDIR");
        snprintf(g_dir, sizeof g_dir, "%s/animkit_fuzz_XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
        if (!mkdtemp(g_dir)) abort();
        snprintf(g_path, sizeof g_path, "%s/in.obj", g_dir);
        atexit(remove_tmp);
    }
    FILE* f = fopen(g_path, "wb");
    if (!f) abort();
    if (size && fwrite(data, 1, size, f) != size) abort();
    fclose(f);
    ak_scene* scene = NULL;
    ak_diag diag;
    ak_io_desc desc = {.format = AK_IO_FORMAT_ASSIMP, .memory_budget = 64u << 20};
    if (ak_io_load(g_path, &desc, NULL, &scene, &diag) == AK_OK) {
        for (size_t m = 0; m < scene->mesh_count; ++m) {
            ak_diag bad = {0};
            if (ak_mesh_validate(scene->meshes[m].mesh, &bad) != AK_OK) {
                fprintf(stderr, "fuzz_obj: loaded mesh %zu fails ak_mesh_validate: %s\n", m, bad.message);
                abort();
            }
        }
    }
    ak_scene_destroy(scene);
    return 0;
}
