/* ik_reach: one arm (shoulder, elbow, wrist, hand tip) reaches for the same target with each
 * IK solver: CCD, FABRIK, two-bone (shoulder-elbow-wrist) and DLS. Prints reached, error,
 * iterations and the chain's joint positions before and after, as `animkit ik` does. */
#include <animkit/ik.h>

#include <stdio.h>
#include <string.h>

static void print_chain(const char* label, const ak_skeleton* sk, const ak_transform* pose, size_t joint_count,
                        const int16_t* chain, size_t chain_count) {
    ak_vec3 pos[8];
    ak_ik_chain_positions(sk, (ak_transform_cspan){pose, joint_count}, (ak_i16_cspan){chain, chain_count},
                          (ak_vec3_span){pos, chain_count});
    printf("  %-7s", label);
    for (size_t i = 0; i < chain_count; ++i)
        printf(" %s(%.3f %.3f %.3f)", ak_skeleton_joint_name(sk, (size_t)chain[i]), pos[i].x, pos[i].y, pos[i].z);
    printf("\n");
}

int main(void) {
    /* A right arm along +x: the elbow is a hinge about y that bends 0..2.6 rad (forward, -z),
     * the shoulder a ball joint with a 1.6 rad cone about the upper arm. */
    ak_joint_desc joints[5] = {
        {.name = "chest", .parent = -1, .rest = ak_transform_identity()},
        {.name = "shoulder", .parent = 0, .rest = {{0.2f, 1.4f, 0}, {0, 0, 0, 1}, {1, 1, 1}}, .type = AK_JOINT_BALL,
         .limits = {.axis = {1, 0, 0}, .cone_angle = 1.6f}},
        {.name = "elbow", .parent = 1, .rest = {{0.3f, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}, .type = AK_JOINT_HINGE,
         .limits = {.axis = {0, 1, 0}, .min = 0.0f, .max = 2.6f}},
        {.name = "wrist", .parent = 2, .rest = {{0.28f, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}},
        {.name = "tip", .parent = 3, .rest = {{0.1f, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}},
    };
    ak_skeleton* sk = NULL;
    ak_skeleton_desc desc = {.joints = joints, .joint_count = 5, .name = "arm"};
    if (ak_skeleton_create(&desc, NULL, &sk, NULL) != AK_OK) return 1;

    const ak_vec3 target = ak_vec3_make(0.45f, 1.55f, -0.3f); /* in front of the shoulder */
    const ak_ik_solver solvers[4] = {AK_IK_SOLVER_CCD, AK_IK_SOLVER_FABRIK, AK_IK_SOLVER_TWO_BONE, AK_IK_SOLVER_DLS};
    unsigned char scratch[4096];
    printf("target (%.3f %.3f %.3f)\n", target.x, target.y, target.z);
    for (int s = 0; s < 4; ++s) {
        /* Two-bone drives shoulder-elbow-wrist; the others the whole arm to the tip. */
        const char* effector = solvers[s] == AK_IK_SOLVER_TWO_BONE ? "wrist" : "tip";
        int16_t chain[8];
        size_t chain_count = 0;
        ak_result r = ak_ik_chain_build(sk, ak_skeleton_find_joint(sk, "shoulder"), ak_skeleton_find_joint(sk, effector),
                                        (ak_i16_span)AK_SPAN(chain), &chain_count);
        if (r != AK_OK) return 1;
        ak_transform pose[5];
        memcpy(pose, ak_skeleton_rest_pose(sk).ptr, sizeof pose);

        bool reached = false;
        float error = 0.0f;
        size_t iterations = 0;
        ak_ik_chain_job job = {
            .skeleton = sk,
            .pose = AK_SPAN(pose),
            .chain = {chain, chain_count},
            .target = target,
            .solver = solvers[s],
            .max_iterations = 100,
            .pole = ak_vec3_make(0, -1, 0), /* two-bone: elbow points down */
            .scratch = AK_SPAN(scratch),
            .out_reached = &reached,
            .out_error = &error,
            .out_iterations = &iterations,
        };
        if (ak_ik_chain_scratch_size(job.solver, chain_count) > sizeof scratch) return 1;
        printf("%s: shoulder..%s\n", ak_ik_solver_name(solvers[s]), effector);
        print_chain("before", sk, ak_skeleton_rest_pose(sk).ptr, 5, chain, chain_count);
        r = ak_ik_chain_run(&job);
        if (r != AK_OK) {
            printf("  error: %s\n", ak_result_string(r));
            return 1;
        }
        print_chain("after", sk, pose, 5, chain, chain_count);
        printf("  reached %s, error %.2e, iterations %zu, elbow within limits %s\n", reached ? "yes" : "no",
               (double)error, iterations, ak_skeleton_joint_within_limits(sk, 2, pose[2], 1e-4f) ? "yes" : "no");
    }

    /* Unreachable: the arm straightens towards the target and says how far it stays. */
    int16_t chain[8];
    size_t chain_count = 0;
    ak_ik_chain_build(sk, 1, 4, (ak_i16_span)AK_SPAN(chain), &chain_count);
    ak_transform pose[5];
    memcpy(pose, ak_skeleton_rest_pose(sk).ptr, sizeof pose);
    bool reached = true;
    float error = 0.0f;
    ak_ik_chain_job far = {.skeleton = sk,
                           .pose = AK_SPAN(pose),
                           .chain = {chain, chain_count},
                           .target = ak_vec3_make(2.0f, 1.0f, 0.5f),
                           .scratch = AK_SPAN(scratch),
                           .out_reached = &reached,
                           .out_error = &error};
    if (ak_ik_chain_run(&far) != AK_OK) return 1;
    printf("unreachable (fabrik): reached %s, remaining distance %.4f\n", reached ? "yes" : "no", (double)error);
    ak_skeleton_destroy(sk);
    return 0;
}
