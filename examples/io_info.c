/* io_info: load an asset (glTF, GLB, BVH, FBX, OBJ, ...) and print what it holds.
 * Usage: example_io_info [FILE]; without FILE it looks for the shared Fox.glb and prints
 * "no assets" (exit 0) when that is absent. Also writes the bind pose to io_info.obj. */
#include <animkit/io.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* find_default(char* buf, size_t size) {
    static const char* const dirs[] = {"../shared/assets", "../../shared/assets", "../../../shared/assets",
                                       "../../../../shared/assets"};
    const char* env = getenv("ANIMKIT_ASSETS");
    if (env && *env) {
        snprintf(buf, size, "%s/gltf/Fox/glTF-Binary/Fox.glb", env);
        FILE* f = fopen(buf, "rb");
        if (f) {
            fclose(f);
            return buf;
        }
    }
    for (size_t i = 0; i < sizeof dirs / sizeof dirs[0]; ++i) {
        snprintf(buf, size, "%s/gltf/Fox/glTF-Binary/Fox.glb", dirs[i]);
        FILE* f = fopen(buf, "rb");
        if (f) {
            fclose(f);
            return buf;
        }
    }
    return NULL;
}

int main(int argc, char** argv) {
    char buf[1024];
    const char* path = argc > 1 ? argv[1] : find_default(buf, sizeof buf);
    if (!path) {
        printf("no assets\n");
        return 0;
    }
    ak_scene* scene = NULL;
    ak_diag diag;
    ak_io_desc desc = {.max_influences = 4};
    ak_result r = ak_io_load(path, &desc, NULL, &scene, &diag);
    if (r != AK_OK) {
        fprintf(stderr, "%s: %s (%s)\n", diag.path, diag.message, ak_result_name(r));
        return 1;
    }
    size_t joints = ak_scene_joint_count(scene);
    printf("%s: %zu joint%s, %zu mesh%s, %zu skin%s, %zu clip%s\n", scene->name, joints, joints == 1 ? "" : "s",
           scene->mesh_count, scene->mesh_count == 1 ? "" : "es", scene->skin_count, scene->skin_count == 1 ? "" : "s",
           scene->clip_count, scene->clip_count == 1 ? "" : "s");
    for (size_t j = 0; j < joints && j < 8; ++j) {
        int parent = ak_skeleton_parents(scene->skeleton).ptr[j];
        printf("  joint %zu %-24s parent %d%s\n", j, ak_skeleton_joint_name(scene->skeleton, j), parent,
               scene->is_joint && !scene->is_joint[j] ? " (node)" : "");
    }
    if (joints > 8) printf("  ... %zu more joints\n", joints - 8);
    for (size_t m = 0; m < scene->mesh_count; ++m) {
        const ak_mesh* mesh = scene->meshes[m].mesh;
        printf("  mesh %zu %-20s %zu vertices, %zu triangles, %u influences, %zu morph targets, skin %d\n", m,
               mesh->name, mesh->vertex_count, mesh->triangle_count, mesh->influence_count, mesh->morph_target_count,
               scene->meshes[m].skin);
    }
    for (size_t c = 0; c < scene->clip_count; ++c)
        printf("  clip %zu %-20s %.4f s, %zu channels\n", c, ak_clip_name(scene->clips[c]),
               (double)ak_clip_duration(scene->clips[c]), ak_clip_channel_count(scene->clips[c]));
    ak_vec3 lo, hi;
    ak_scene_bounds(scene, &lo, &hi);
    printf("  bounds (%.3f %.3f %.3f) - (%.3f %.3f %.3f)\n", (double)lo.x, (double)lo.y, (double)lo.z, (double)hi.x,
           (double)hi.y, (double)hi.z);
    if (scene->mesh_count) {
        r = ak_io_write_obj("io_info.obj", scene, NULL, NULL, &diag);
        printf("  bind pose -> io_info.obj: %s\n", ak_result_string(r));
    }
    ak_scene_destroy(scene);
    return r == AK_OK ? 0 : 1;
}
