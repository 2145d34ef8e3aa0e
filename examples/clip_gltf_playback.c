/* clip_gltf_playback: loads the Fox glTF (three clips), lists each clip's channels, plays
 * every clip for three loops at 60 Hz with a cursor and checks the frames against the
 * binary-search sampler, then splits the Walk clip's root travel off as root motion.
 * Usage: example_clip_gltf_playback [path/to/Fox.glb]; exits 0 with a note when absent. */
#include <animkit/io.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* find_fox(int argc, char** argv) {
    static char buf[1024];
    const char* env = getenv("ANIMKIT_ASSETS");
    const char* candidates[] = {"../shared/assets", "../../shared/assets", "../../../shared/assets",
                                "../../../../shared/assets"};
    if (argc > 1) return argv[1];
    if (env && *env) {
        snprintf(buf, sizeof buf, "%s/gltf/Fox/glTF-Binary/Fox.glb", env);
        FILE* f = fopen(buf, "rb");
        if (f) return fclose(f), buf;
    }
    for (size_t i = 0; i < sizeof candidates / sizeof candidates[0]; ++i) {
        snprintf(buf, sizeof buf, "%s/gltf/Fox/glTF-Binary/Fox.glb", candidates[i]);
        FILE* f = fopen(buf, "rb");
        if (f) return fclose(f), buf;
    }
    return NULL;
}

int main(int argc, char** argv) {
    const char* path = find_fox(argc, argv);
    if (!path) {
        printf("Fox.glb not found (set ANIMKIT_ASSETS or pass a path); nothing to do\n");
        return 0;
    }
    ak_scene* scene = NULL;
    ak_diag diag;
    ak_result r = ak_io_load(path, NULL, NULL, &scene, &diag);
    if (r != AK_OK) {
        fprintf(stderr, "%s: %s (%s)\n", path, ak_result_string(r), diag.message);
        return 1;
    }
    size_t joints = ak_scene_joint_count(scene);
    ak_transform* rest = malloc(joints * sizeof(ak_transform));
    ak_transform* a = malloc(joints * sizeof(ak_transform));
    ak_transform* b = malloc(joints * sizeof(ak_transform));
    if (!rest || !a || !b) return 1;
    ak_scene_rest_pose(scene, (ak_transform_span){rest, joints});
    printf("%s: %zu joints, %zu clips\n", path, joints, scene->clip_count);
    int status = 0;
    for (size_t c = 0; c < scene->clip_count; ++c) {
        const ak_clip* clip = scene->clips[c];
        size_t nch = ak_clip_channel_count(clip), keys = 0, per_interp[AK_INTERP_COUNT] = {0};
        for (size_t i = 0; i < nch; ++i) {
            keys += ak_clip_channel_key_count(clip, i);
            per_interp[ak_clip_channel_interp(clip, i)]++;
        }
        printf("clip %-8s %.4f s, %zu channels, %zu keys:", ak_clip_name(clip), (double)ak_clip_duration(clip), nch,
               keys);
        for (int m = 0; m < AK_INTERP_COUNT; ++m)
            if (per_interp[m]) printf(" %zu %s", per_interp[m], ak_interp_name((ak_interp)m));
        printf("\n");

        size_t storage = ak_clip_cursor_storage_count(clip);
        uint32_t* seg = malloc((storage ? storage : 1) * sizeof(uint32_t));
        ak_clip_cursor cursor;
        if (!seg || ak_clip_cursor_init(&cursor, clip, (ak_u32_span){seg, storage}) != AK_OK) return 1;
        int frames = 0, mismatches = 0;
        for (float t = 0.0f; t < 3.0f * ak_clip_duration(clip); t += 1.0f / 60.0f, ++frames) {
            float ct = ak_time_wrap(t, ak_clip_duration(clip), AK_WRAP_LOOP);
            memcpy(a, rest, joints * sizeof(ak_transform));
            memcpy(b, rest, joints * sizeof(ak_transform));
            ak_clip_sample(clip, ct, &cursor, (ak_transform_span){a, joints}, (ak_f32_span){0}, (ak_f32_span){0});
            ak_clip_sample(clip, ct, NULL, (ak_transform_span){b, joints}, (ak_f32_span){0}, (ak_f32_span){0});
            if (memcmp(a, b, joints * sizeof(ak_transform)) != 0) ++mismatches;
        }
        printf("  %d frames over 3 loops, cursor vs binary search: %d mismatches\n", frames, mismatches);
        if (mismatches) status = 1;
        free(seg);
    }

    /* Root motion of "Walk": the joint whose translation channel travels furthest in XZ. */
    int walk = ak_scene_find_clip(scene, "Walk");
    if (walk >= 0) {
        const ak_clip* clip = scene->clips[walk];
        uint32_t root = 0;
        float best = -1.0f;
        for (size_t i = 0; i < ak_clip_channel_count(clip); ++i) {
            if (ak_clip_channel_target(clip, i) != AK_CHANNEL_TRANSLATION) continue;
            const ak_track* tr = ak_clip_channel_track(clip, i);
            float p0[3], p1[3];
            ak_track_sample(tr, ak_track_start_time(tr), (ak_f32_span){p0, 3});
            ak_track_sample(tr, ak_track_end_time(tr), (ak_f32_span){p1, 3});
            float d = (p1[0] - p0[0]) * (p1[0] - p0[0]) + (p1[2] - p0[2]) * (p1[2] - p0[2]);
            if (d > best) best = d, root = ak_clip_channel_index(clip, i);
        }
        ak_clip* in_place = NULL;
        ak_track* trajectory = NULL;
        ak_root_motion_desc rm = {.root_joint = root};
        r = ak_clip_extract_root_motion(clip, &rm, NULL, &in_place, &trajectory);
        if (r != AK_OK) {
            fprintf(stderr, "root motion: %s\n", ak_result_string(r));
            return 1;
        }
        float end[3];
        ak_track_sample(trajectory, ak_track_end_time(trajectory), (ak_f32_span){end, 3});
        printf("Walk root joint %u: travel per loop (%.4f, %.4f, %.4f), in-place clip \"%s\"\n", (unsigned)root,
               (double)end[0], (double)end[1], (double)end[2], ak_clip_name(in_place));
        ak_clip_destroy(in_place);
        ak_track_destroy(trajectory);
    }
    free(rest);
    free(a);
    free(b);
    ak_scene_destroy(scene);
    return status;
}
