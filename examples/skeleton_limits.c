/* skeleton_limits: a hip-knee-ankle leg, forward kinematics and joint limits.
 * Builds a skeleton with a ball hip (cone + twist) and a hinge knee, poses it beyond its
 * limits, clamps the pose with ak_skeleton_apply_limits and prints the ankle before/after. */
#include <stdio.h>

#include <animkit/skeleton.h>

static void print_ankle(const char* label, const ak_skeleton* sk, const ak_transform* pose) {
    ak_mat4 model[3];
    ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, 3}, (ak_mat4_span)AK_SPAN(model));
    ak_vec3 p = ak_mat4_get_translation(model[2]);
    printf("%-8s ankle at (%+.3f, %+.3f, %+.3f)", label, (double)p.x, (double)p.y, (double)p.z);
    for (size_t j = 0; j < 3; ++j)
        printf("  %s:%s", ak_skeleton_joint_name(sk, j),
               ak_skeleton_joint_within_limits(sk, j, pose[j], 1e-4f) ? "ok" : "OUT");
    printf("\n");
}

int main(void) {
    const ak_quat id = ak_quat_identity();
    ak_joint_desc joints[3] = {
        {.name = "hip",
         .parent = -1,
         .rest = {{0, 0.9f, 0}, id, {1, 1, 1}},
         .type = AK_JOINT_BALL,
         .limits = {.axis = {0, -1, 0}, .cone_angle = 1.2f, .twist_min = -0.5f, .twist_max = 0.5f}},
        {.name = "knee",
         .parent = 0,
         .rest = {{0, -0.42f, 0}, id, {1, 1, 1}},
         .type = AK_JOINT_HINGE,
         .limits = {.axis = {1, 0, 0}, .min = 0.0f, .max = 2.4f}},
        {.name = "ankle", .parent = 1, .rest = {{0, -0.4f, 0}, id, {1, 1, 1}}},
    };
    ak_skeleton_desc desc = {.joints = joints, .joint_count = 3, .name = "leg"};
    ak_skeleton* sk = NULL;
    ak_diag diag;
    ak_result r = ak_skeleton_create(&desc, NULL, &sk, &diag);
    if (r != AK_OK) {
        fprintf(stderr, "skeleton_limits: %s: %s\n", ak_result_string(r), diag.message);
        return 1;
    }

    /* Rest pose: the ankle hangs 0.82 m below the hip. */
    ak_transform pose[3];
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    for (int j = 0; j < 3; ++j) pose[j] = rest.ptr[j];
    print_ankle("rest", sk, pose);

    /* Kick: hip flexed 100 degrees forward (beyond the 69-degree cone) and twisted; knee bent
     * backwards (-30 degrees, a hinge that only flexes) and sideways. */
    pose[0].rotation = ak_quat_mul(ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), -1.75f),
                                   ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.9f));
    pose[1].rotation = ak_quat_mul(ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), -0.52f),
                                   ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.3f));
    print_ankle("posed", sk, pose);
    ak_skeleton_apply_limits(sk, (ak_transform_span){pose, 3});
    print_ankle("clamped", sk, pose);

    /* The same clamp, one joint at a time, for a knee bent 3 radians (max 2.4). */
    ak_transform knee = rest.ptr[1];
    knee.rotation = ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 3.0f);
    ak_transform k2 = ak_skeleton_limit_joint(sk, 1, knee);
    ak_vec3 axis;
    float angle;
    ak_quat_to_axis_angle(k2.rotation, &axis, &angle);
    printf("knee 3.000 rad -> %.3f rad about (%.0f, %.0f, %.0f)\n", (double)angle, (double)axis.x,
           (double)axis.y, (double)axis.z);
    ak_skeleton_destroy(sk);
    return 0;
}
