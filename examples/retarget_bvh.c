/* retarget_bvh: put CMU motion capture (a BVH walk) on the builtin humanoid, mapped
 * automatically (humanoid template), with and without the foot-contact clean-up, and write
 * the result as retarget_bvh.glb.
 * Usage: example_retarget_bvh [FILE.bvh]; without FILE it looks for the shared 02_01.bvh and
 * prints "no assets" (exit 0) when that is absent. */
#include <animkit/animkit.h>
#include <stdio.h>
#include <stdlib.h>

static const char* find_default(char* buf, size_t size) {
    static const char* const dirs[] = {"../shared/assets", "../../shared/assets", "../../../shared/assets",
                                       "../../../../shared/assets"};
    const char* env = getenv("ANIMKIT_ASSETS");
    for (size_t i = 0; i <= sizeof dirs / sizeof dirs[0]; ++i) {
        const char* d = i == 0 ? env : dirs[i - 1];
        if (!d || !*d) continue;
        snprintf(buf, size, "%s/bvh/02_01.bvh", d);
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
        printf("no assets (set ANIMKIT_ASSETS or pass a .bvh file)\n");
        return 0;
    }
    ak_scene *mocap = NULL, *human = NULL;
    ak_diag diag;
    if (ak_io_load(path, NULL, NULL, &mocap, &diag) != AK_OK || mocap->clip_count == 0) {
        fprintf(stderr, "%s: %s\n", path, mocap ? "no clip" : diag.message);
        ak_scene_destroy(mocap);
        return 1;
    }
    if (ak_builtin_create("humanoid", NULL, NULL, &human) != AK_OK) return 1;

    /* which target joint follows which source joint: both skeletons fitted to the humanoid
     * template (topology, rest pose, name hints), then paired bone by bone; the table printed
     * is a map file (animkit retarget --map reads it) */
    size_t nt = ak_scene_joint_count(human);
    int32_t* map = malloc(nt * sizeof *map);
    ak_humanoid_roles sr, tr;
    if (ak_humanoid_roles_find(mocap->skeleton, NULL, &sr, &diag) != AK_OK ||
        ak_humanoid_roles_find(human->skeleton, NULL, &tr, &diag) != AK_OK) {
        fprintf(stderr, "%s\n", diag.message); /* e.g. "not a humanoid: ..." */
        return 1;
    }
    ak_retarget_map_by_roles(mocap->skeleton, &sr, human->skeleton, &tr, (ak_i32_span){map, nt}, NULL);
    char table[8192];
    ak_retarget_map_write(mocap->skeleton, &sr, human->skeleton, &tr, (ak_i32_cspan){map, nt}, table, sizeof table, NULL);
    fputs(table, stdout);

    ak_clip* clip[2] = {NULL, NULL};
    for (int clean = 0; clean < 2; ++clean) {
        ak_retarget_desc d = {.source = mocap->skeleton, .clip = mocap->clips[0], .target = human->skeleton,
                              .source_of_target = {map, nt}, .skip_foot_contacts = !clean};
        ak_retarget_stats st;
        if (ak_retarget_clip(&d, NULL, &clip[clean], &st, &diag) != AK_OK) {
            fprintf(stderr, "retarget: %s\n", diag.message);
            return 1;
        }
        printf("%s clean-up: %zu frames, %zu/%zu joints, root motion x%.4f, %zu foot frames in contact, %zu pinned\n",
               clean ? "with" : "without", st.frame_count, st.mapped_count, nt, (double)st.root_scale,
               st.contact_frames, st.pinned_frames);
    }

    ak_scene out = *human; /* the humanoid with the cleaned clip only */
    out.clips = &clip[1];
    out.clip_count = 1;
    ak_result r = ak_io_save("retarget_bvh.glb", &out, NULL, &diag);
    if (r != AK_OK) fprintf(stderr, "%s: %s\n", diag.path, diag.message);
    else printf("wrote retarget_bvh.glb\n");
    ak_clip_destroy(clip[0]);
    ak_clip_destroy(clip[1]);
    free(map);
    ak_scene_destroy(mocap);
    ak_scene_destroy(human);
    return r == AK_OK ? 0 : 1;
}
