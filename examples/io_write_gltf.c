/* io_write_gltf: compute a motion (a two-bone IK reach on the builtin humanoid), bake the
 * solved poses into a clip with ak_clip_bake and write the character with it as glTF 2.0
 * (io_write_gltf.glb, viewable in three.js, Blender, Godot); then read it back and check. */
#include <animkit/animkit.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(void) {
    ak_scene* scene = NULL;
    if (ak_builtin_create("humanoid", NULL, NULL, &scene) != AK_OK) return 1;
    const ak_skeleton* sk = scene->skeleton;
    size_t n = ak_skeleton_joint_count(sk);
    int shoulder = ak_skeleton_find_joint(sk, "right_shoulder");
    int elbow = ak_skeleton_find_joint(sk, "right_elbow");
    int wrist = ak_skeleton_find_joint(sk, "right_wrist");
    if (shoulder < 0 || elbow < 0 || wrist < 0) return 1;

    /* 2 s at 30 fps: the right hand follows a circle in front of the chest */
    enum { FRAMES = 61 };
    ak_transform* poses = malloc(FRAMES * n * sizeof *poses);
    ak_mat4* model = malloc(n * sizeof *model);
    if (!poses || !model) return 1;
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    ak_skeleton_local_to_model(sk, rest, (ak_mat4_span){model, n});
    ak_vec3 centre = ak_mat4_get_translation(model[shoulder]);
    centre = ak_vec3_add(centre, ak_vec3_make(-0.15f, -0.1f, 0.35f));
    int reached = 0;
    for (int f = 0; f < FRAMES; ++f) {
        ak_transform* local = poses + (size_t)f * n;
        memcpy(local, rest.ptr, n * sizeof *local);
        ak_skeleton_local_to_model(sk, (ak_transform_cspan){local, n}, (ak_mat4_span){model, n});
        float a = 6.2831853f * (float)f / (float)(FRAMES - 1);
        ak_vec3 target = ak_vec3_add(centre, ak_vec3_make(0.15f * cosf(a), 0.15f * sinf(a), 0.0f));
        ak_quat fix_s, fix_e;
        bool ok = false;
        ak_ik_two_bone_job job = {.start = model[shoulder], .mid = model[elbow], .end = model[wrist],
                                  .target = target, .pole = ak_vec3_make(0, -1, -1),
                                  .out_start_rot = &fix_s, .out_mid_rot = &fix_e, .out_reached = &ok};
        if (ak_ik_two_bone_run(&job) != AK_OK) return 1;
        local[shoulder].rotation = ak_quat_mul(local[shoulder].rotation, fix_s);
        local[elbow].rotation = ak_quat_mul(local[elbow].rotation, fix_e);
        reached += ok;
    }

    /* bake: one key per frame, joints that never leave the rest pose get no channel */
    ak_clip* clip = NULL;
    ak_diag diag;
    ak_clip_bake_desc bake = {.poses = poses, .frame_count = FRAMES, .joint_count = n, .frame_rate = 30.0f,
                              .rest_pose = rest, .name = "reach_circle"};
    if (ak_clip_bake(&bake, NULL, &clip, &diag) != AK_OK) {
        fprintf(stderr, "bake: %s\n", diag.message);
        return 1;
    }
    printf("baked %d frames (%d reached), %zu channels, %.2f s\n", FRAMES, reached, ak_clip_channel_count(clip),
           (double)ak_clip_duration(clip));

    /* write the character with only this clip (a shallow copy keeps the scene's own clips) */
    ak_scene out = *scene;
    out.clips = &clip;
    out.clip_count = 1;
    if (ak_io_save("io_write_gltf.glb", &out, NULL, &diag) != AK_OK) {
        fprintf(stderr, "%s: %s\n", diag.path, diag.message);
        return 1;
    }

    /* read it back: the hand is where the IK put it */
    ak_scene* back = NULL;
    if (ak_io_load("io_write_gltf.glb", NULL, NULL, &back, &diag) != AK_OK) {
        fprintf(stderr, "%s: %s\n", diag.path, diag.message);
        return 1;
    }
    size_t nb = ak_scene_joint_count(back);
    ak_transform* lb = malloc(nb * sizeof *lb);
    ak_mat4* mb = malloc(nb * sizeof *mb);
    int wb = ak_skeleton_find_joint(back->skeleton, "right_wrist");
    double worst = 0;
    for (int f = 0; f < FRAMES && lb && mb && wb >= 0; ++f) {
        ak_scene_rest_pose(back, (ak_transform_span){lb, nb});
        ak_clip_sample(back->clips[0], (float)f / 30.0f, NULL, (ak_transform_span){lb, nb}, (ak_f32_span){0},
                       (ak_f32_span){0});
        ak_scene_world_matrices(back, (ak_transform_cspan){lb, nb}, (ak_mat4_span){mb, nb});
        ak_skeleton_local_to_model(sk, (ak_transform_cspan){poses + (size_t)f * n, n}, (ak_mat4_span){model, n});
        ak_vec3 d = ak_vec3_sub(ak_mat4_get_translation(mb[wb]), ak_mat4_get_translation(model[wrist]));
        worst = fmax(worst, ak_vec3_length(d));
    }
    printf("wrote io_write_gltf.glb: %zu joints, %zu mesh%s, 1 clip; hand after reload within %.2g m\n", nb,
           back->mesh_count, back->mesh_count == 1 ? "" : "es", worst);
    free(lb);
    free(mb);
    free(poses);
    free(model);
    ak_scene_destroy(back);
    ak_clip_destroy(clip);
    ak_scene_destroy(scene);
    return worst < 1e-4 ? 0 : 1;
}
