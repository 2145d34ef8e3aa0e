/* libFuzzer target for animkit's own OBJ + MTL reader (src/io/obj.c); built and run by
 * scripts/fuzz.sh. (fuzz_obj.c fuzzes the Assimp path.)
 *
 * An input is an OBJ and an MTL in one: the bytes before the first line "#MTL" are written to
 * in.obj, the rest to s.mtl, both alone in a private directory (mkdtemp in $TMPDIR or /tmp,
 * removed at exit), and in.obj is loaded from there with AUTO (the .obj extension picks the
 * reader). An "mtllib" line names s.mtl or nothing that exists, so a run depends on no
 * other file. A loaded scene must validate: meshes (indices in range, finite values), nodes
 * in range, materials' colours finite. */
#include <animkit/io.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static char g_dir[4096], g_obj[4096 + 16], g_mtl[4096 + 16];

static void remove_tmp(void) {
    unlink(g_obj);
    unlink(g_mtl);
    rmdir(g_dir);
}

static void write_part(const char* path, const uint8_t* p, size_t n) {
    FILE* f = fopen(path, "wb");
    if (!f) abort();
    if (n && fwrite(p, 1, n, f) != n) abort();
    fclose(f);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (!g_obj[0]) {
        const char* tmp = getenv("TMPDIR");
        snprintf(g_dir, sizeof g_dir, "%s/animkit_fuzz_XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
        if (!mkdtemp(g_dir)) abort();
        snprintf(g_obj, sizeof g_obj, "%s/in.obj", g_dir);
        snprintf(g_mtl, sizeof g_mtl, "%s/s.mtl", g_dir);
        atexit(remove_tmp);
    }
    size_t split = size;
    for (size_t i = 0; i + 4 <= size; ++i)
        if ((i == 0 || data[i - 1] == '\n') && memcmp(data + i, "#MTL", 4) == 0) {
            split = i;
            break;
        }
    write_part(g_obj, data, split);
    write_part(g_mtl, data + split, size - split);
    ak_scene* scene = NULL;
    ak_diag diag;
    ak_io_desc desc = {.memory_budget = 64u << 20};
    if (ak_io_load(g_obj, &desc, NULL, &scene, &diag) == AK_OK) {
        size_t joints = ak_scene_joint_count(scene);
        for (size_t m = 0; m < scene->mesh_count; ++m) {
            const ak_scene_mesh* sm = &scene->meshes[m];
            ak_diag bad = {0};
            if (ak_mesh_validate(sm->mesh, &bad) != AK_OK) {
                fprintf(stderr, "fuzz_obj_mtl: loaded mesh %zu fails ak_mesh_validate: %s\n", m, bad.message);
                abort();
            }
            if (sm->node < -1 || sm->node >= (int32_t)joints || sm->skin != -1) abort();
            if (sm->has_material && !(isfinite(sm->base_color.x) && isfinite(sm->base_color.y) &&
                                      isfinite(sm->base_color.z) && isfinite(sm->base_color.w)))
                abort();
            for (size_t v = 0; sm->mesh->uvs && v < sm->mesh->vertex_count; ++v)
                if (!isfinite(sm->mesh->uvs[v].x) || !isfinite(sm->mesh->uvs[v].y)) abort();
        }
    } else {
        /* an error message holds printable ASCII or valid UTF-8 only: no raw control byte */
        for (const char* c = diag.message; *c; ++c)
            if ((unsigned char)*c < 0x20 || *c == 0x7F) abort();
    }
    ak_scene_destroy(scene);
    return 0;
}
