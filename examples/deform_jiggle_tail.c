/* deform_jiggle_tail: follow-through on a 4-joint tail hanging off a swaying hip, plus a bent and
 * twisted prop. The hip swings for one second and stops; the tail lags, overshoots and settles.
 * Prints the tail tip's distance from its animated (un-jiggled) position per frame. */
#include <math.h>
#include <stdio.h>

#include <animkit/deform.h>

enum { N = 6 };
static const int32_t parents[N] = {-1, 0, 1, 2, 3, 4}; /* root, hip, tail0..tail3 */
static const ak_vec3 offsets[N] = {{0, 0, 0}, {0, 1, 0}, {0, 0, -0.1f}, {0, 0, -0.25f}, {0, 0, -0.25f}, {0, 0, -0.25f}};

int main(void) {
    ak_jiggle_joint tail[4] = {
        {.joint = 2, .tip = {0, 0, -0.25f}}, {.joint = 3, .tip = {0, 0, -0.25f}},
        {.joint = 4, .tip = {0, 0, -0.25f}}, {.joint = 5, .tip = {0, 0, -0.25f}},
    };
    static ak_jiggle_state state[4]; /* zero -> starts at rest */
    ak_mat4 model[N], jiggled[N];
    const float fps = 60.0f;
    printf("%6s %10s %10s\n", "t", "hip yaw", "tip lag");
    for (int f = 0; f <= 150; ++f) {
        float t = (float)f / fps;
        float yaw = t < 1.0f ? 0.6f * sinf(AK_TWO_PI * t) : 0.0f;
        /* Forward kinematics of the animated pose (a skeleton would do this: ak_skeleton_local_to_model). */
        for (int i = 0; i < N; ++i) {
            ak_mat4 local = ak_mat4_translation(offsets[i]);
            if (i == 1) local = ak_mat4_mul(local, ak_mat4_from_quat(ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), yaw)));
            model[i] = parents[i] < 0 ? local : ak_mat4_mul(model[parents[i]], local);
        }
        ak_jiggle_job job = {
            .params = {.stiffness = 120.0f, .damping = 10.0f, .gravity = {0, -2.0f, 0}},
            .parents = {parents, N}, .joints = tail, .joint_count = 4, .states = AK_SPAN(state),
            .model = {model, N}, .dt = 1.0f / fps, .out_model = {jiggled, N},
        };
        ak_result r = ak_jiggle_run(&job);
        if (r != AK_OK) {
            fprintf(stderr, "jiggle: %s\n", ak_result_string(r));
            return 1;
        }
        ak_vec3 tip_anim = ak_mat4_transform_point(model[5], tail[3].tip);
        ak_vec3 tip_jig = ak_mat4_transform_point(jiggled[5], tail[3].tip);
        if (f % 5 == 0) printf("%6.3f %10.4f %10.4f\n", t, yaw, ak_vec3_distance(tip_anim, tip_jig));
    }
    /* A cartoon prop: a 1 m rod along +Y bent 90 degrees towards +X, then twisted half a turn. */
    ak_deformer stack[2] = {
        {.type = AK_DEFORMER_BEND, .axis = {0, 1, 0}, .bend_direction = {1, 0, 0}, .amount = AK_HALF_PI, .length = 1.0f},
        {.type = AK_DEFORMER_TWIST, .axis = {0, 1, 0}, .amount = AK_PI, .length = 1.0f},
    };
    ak_vec3 rod[5], bent[5];
    for (int i = 0; i < 5; ++i) rod[i] = ak_vec3_make(0.05f, 0.25f * (float)i, 0);
    ak_deform_job dj = {.deformers = stack, .deformer_count = 2, .positions = AK_SPAN(rod), .out_positions = AK_SPAN(bent)};
    if (ak_deform_run(&dj) != AK_OK) return 1;
    for (int i = 0; i < 5; ++i) printf("rod %d: (%.3f %.3f %.3f)\n", i, bent[i].x, bent[i].y, bent[i].z);
    return 0;
}
