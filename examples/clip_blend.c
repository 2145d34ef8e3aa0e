/* clip_blend: builds two small clips for a 3-joint leg (walk and kick), plays them with
 * cursors, cross-fades from one to the other with an eased weight, and extracts the walk's
 * root motion. Prints the root and foot values per frame. */
#include <animkit/clip.h>

#include <stdio.h>

enum { JOINTS = 3 };

static ak_clip* make_clip(const char* name, float stride, float swing) {
    const float times[3] = {0.0f, 0.5f, 1.0f};
    /* Root translation (joint 0): moves forward by stride per cycle and bobs. */
    const float root[9] = {0, 1, 0, 0.5f * stride, 1.05f, 0, stride, 1, 0};
    /* Hip rotation (joint 1) about X: swings forward and back. */
    ak_quat a = ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), -swing);
    ak_quat b = ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), swing);
    const float hip[12] = {a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, a.x, a.y, a.z, a.w};
    const ak_raw_channel ch[2] = {
        {.target = AK_CHANNEL_TRANSLATION, .index = 0, .interp = AK_INTERP_CARDINAL, .key_count = 3,
         .times = times, .values = root},
        {.target = AK_CHANNEL_ROTATION, .index = 1, .key_count = 3, .times = times, .values = hip},
    };
    ak_raw_clip raw = {.name = name, .channels = ch, .channel_count = 2, .joint_count = JOINTS};
    ak_clip* clip = NULL;
    ak_diag diag;
    if (ak_clip_build(&raw, NULL, &clip, &diag) != AK_OK) fprintf(stderr, "%s: %s\n", name, diag.message);
    return clip;
}

int main(void) {
    ak_clip* walk = make_clip("walk", 1.4f, 0.5f);
    ak_clip* kick = make_clip("kick", 0.0f, 1.2f);
    if (!walk || !kick) return 1;
    ak_transform rest[JOINTS], a[JOINTS], b[JOINTS], out[JOINTS];
    for (int j = 0; j < JOINTS; ++j) rest[j] = ak_transform_identity();
    uint32_t seg_a[8], seg_b[8];
    ak_clip_cursor ca, cb;
    ak_clip_cursor_init(&ca, walk, (ak_u32_span)AK_SPAN(seg_a));
    ak_clip_cursor_init(&cb, kick, (ak_u32_span)AK_SPAN(seg_b));

    printf("%5s %6s %8s %8s %9s\n", "t", "fade", "root.x", "root.y", "hip.angle");
    for (int f = 0; f <= 24; ++f) {
        float t = (float)f / 12.0f;
        for (int j = 0; j < JOINTS; ++j) a[j] = b[j] = rest[j];
        ak_clip_sample(walk, ak_time_wrap(t, ak_clip_duration(walk), AK_WRAP_LOOP), &ca,
                       (ak_transform_span)AK_SPAN(a), (ak_f32_span){0}, (ak_f32_span){0});
        ak_clip_sample(kick, ak_time_wrap(t, ak_clip_duration(kick), AK_WRAP_PING_PONG), &cb,
                       (ak_transform_span)AK_SPAN(b), (ak_f32_span){0}, (ak_f32_span){0});
        /* Cross-fade from walk to kick between t = 0.5 s and 1.5 s, slow in and slow out. */
        float alpha = ak_ease(AK_EASE_SMOOTHSTEP, (t - 0.5f) / 1.0f);
        ak_pose_crossfade((ak_transform_cspan)AK_SPAN(a), (ak_transform_cspan)AK_SPAN(b), alpha,
                          (ak_transform_span)AK_SPAN(out));
        ak_vec3 axis;
        float angle;
        ak_quat_to_axis_angle(out[1].rotation, &axis, &angle);
        printf("%5.2f %6.3f %8.4f %8.4f %9.4f\n", (double)t, (double)alpha, (double)out[0].translation.x,
               (double)out[0].translation.y, (double)(axis.x < 0 ? -angle : angle));
    }

    /* Upper/lower split with a mask: joint 1 from kick, everything else from walk. */
    float mask[JOINTS] = {0, 1, 0};
    ak_blend_layer layers[2] = {{.pose = {a, JOINTS}, .weight = 1.0f},
                                {.pose = {b, JOINTS}, .weight = 1.0f, .joint_weights = {mask, JOINTS}}};
    ak_blend_job job = {.layers = layers, .layer_count = 2, .rest_pose = {rest, JOINTS},
                        .out_local = {out, JOINTS}};
    ak_result r = ak_blend_run(&job);
    printf("masked blend: %s, root.x %.4f (walk %.4f)\n", ak_result_name(r), (double)out[0].translation.x,
           (double)a[0].translation.x);

    /* Root motion: the walk in place plus the trajectory the game applies. */
    ak_clip* in_place = NULL;
    ak_track* trajectory = NULL;
    if (ak_clip_extract_root_motion(walk, NULL, NULL, &in_place, &trajectory) != AK_OK) return 1;
    for (int f = 0; f <= 4; ++f) {
        float t = 0.25f * (float)f, d[3];
        for (int j = 0; j < JOINTS; ++j) a[j] = rest[j];
        ak_clip_sample(in_place, t, NULL, (ak_transform_span)AK_SPAN(a), (ak_f32_span){0}, (ak_f32_span){0});
        ak_track_sample(trajectory, t, (ak_f32_span){d, 3});
        printf("in place t=%.2f root=(%.3f, %.3f, %.3f) trajectory=(%.3f, %.3f, %.3f)\n", (double)t,
               (double)a[0].translation.x, (double)a[0].translation.y, (double)a[0].translation.z, (double)d[0],
               (double)d[1], (double)d[2]);
    }
    ak_clip_destroy(in_place);
    ak_track_destroy(trajectory);
    ak_clip_destroy(walk);
    ak_clip_destroy(kick);
    return 0;
}
