/* A ragdoll from builtin:humanoid, started from its walk clip's pose and velocities (or the
 * rest pose), dropped onto the ground: every written-back joint stays within the skeleton's own
 * limits (checked by ak_skeleton_joint_within_limits, 2 degrees), no body goes through the
 * ground, the joints hold together, and the pose read back skins to finite matrices. */
#include <math.h>
#include <stdlib.h>

#include <animkit/animkit.h>

#include "ak_test.h"

typedef struct drop_result {
    bool ok;
    float worst_limit_deg; /* the largest tolerance a joint needed beyond 2 degrees, else 0 */
    float lowest;          /* lowest point of any capsule (m) */
    float worst_gap;       /* largest distance between a joint's anchors (m) */
    bool finite;
} drop_result;

/* 0 when joint i's local transform meets its limits within 2 degrees, else the smallest
 * tolerance (rad) within which it does. */
static float limit_excess(const ak_skeleton* sk, size_t i, ak_transform local) {
    if (ak_skeleton_joint_within_limits(sk, i, local, ak_radians(2.0f))) return 0.0f; /* enough */
    float lo = 1e-4f, hi = 3.2f;
    if (!ak_skeleton_joint_within_limits(sk, i, local, hi)) return hi;
    for (int it = 0; it < 30; ++it) {
        float mid = 0.5f * (lo + hi);
        if (ak_skeleton_joint_within_limits(sk, i, local, mid))
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

static drop_result drop(bool animated, float seconds) {
    drop_result res = {.ok = false, .lowest = INFINITY, .finite = true};
    ak_scene* scene = NULL;
    /* the coarsest skin: only the skeleton matters here */
    ak_builtin_desc bd = {.cell_size = 0.1f};
    if (ak_builtin_create("humanoid", &bd, NULL, &scene) != AK_OK) return res;
    const ak_skeleton* sk = scene->skeleton;
    size_t n = ak_skeleton_joint_count(sk);
    ak_transform* pose = malloc(n * sizeof *pose);
    ak_transform* prev = malloc(n * sizeof *prev);
    ak_transform* back = malloc(n * sizeof *back);
    ak_mat4* world = malloc(n * sizeof *world);
    size_t nb = ak_rigid_ragdoll_body_count(sk) + 1, nj = ak_rigid_ragdoll_joint_count(sk);
    ak_rigid_body_desc* bodies = calloc(nb, sizeof *bodies);
    ak_rigid_joint_desc* joints = calloc(nj + 1, sizeof *joints);
    ak_rigid_ragdoll_bone* bones = calloc(n, sizeof *bones);
    ak_vec3 *x = calloc(nb, sizeof *x), *v = calloc(nb, sizeof *v), *w = calloc(nb, sizeof *w);
    ak_quat* q = calloc(nb, sizeof *q);
    ak_rigid_model* m = NULL;
    ak_rigid_step_job job = {0};
    if (!pose || !prev || !back || !world || !bodies || !joints || !bones || !x || !v || !w || !q)
        goto done;
    ak_scene_rest_pose(scene, (ak_transform_span){pose, n});
    ak_scene_rest_pose(scene, (ak_transform_span){prev, n});
    if (animated && scene->clip_count > 0) {
        const ak_clip* clip = scene->clips[0];
        float t = 0.3f * ak_clip_duration(clip);
        ak_clip_sample(clip, t, NULL, (ak_transform_span){pose, n}, (ak_f32_span){0},
                       (ak_f32_span){0});
        ak_clip_sample(clip, t - 1.0f / 60.0f, NULL, (ak_transform_span){prev, n}, (ak_f32_span){0},
                       (ak_f32_span){0});
    }
    /* half a metre up, body 0 the ground */
    ak_mat4 root = ak_mat4_translation(ak_vec3_make(0.0f, 0.5f, 0.0f));
    bodies[0].shape.type = AK_RIGID_PLANE;
    ak_rigid_ragdoll_desc rd = {
        .skeleton = sk, .local_pose = {pose, n}, .root = root, .body_offset = 1};
    if (animated) rd.previous_pose = (ak_transform_cspan){prev, n}, rd.previous_dt = 1.0f / 60.0f;
    if (ak_rigid_ragdoll_build(&rd, (ak_rigid_body_desc_span){bodies + 1, nb - 1},
                               (ak_rigid_joint_desc_span){joints, nj},
                               (ak_rigid_ragdoll_bone_span){bones, n}) != AK_OK)
        goto done;
    ak_rigid_model_desc md = {.bodies = {bodies, nb}, .joints = {joints, nj}};
    if (ak_rigid_model_create(&md, NULL, &m) != AK_OK) goto done;
    ak_rigid_initial_state(m, (ak_vec3_span){x, nb}, (ak_quat_span){q, nb}, (ak_vec3_span){v, nb},
                           (ak_vec3_span){w, nb});
    job = (ak_rigid_step_job){.model = m,
                              .dt = 1.0f / 60.0f,
                              .substeps = 40,
                              .gravity = {0, -9.81f, 0},
                              .positions = {x, nb},
                              .orientations = {q, nb},
                              .velocities = {v, nb},
                              .angular_velocities = {w, nb}};
    size_t size = ak_rigid_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    if (!job.scratch.ptr) goto done;
    res.ok = true;
    for (int f = 0; f < (int)(seconds * 60.0f); ++f) {
        if (ak_rigid_step_run(&job) != AK_OK) {
            res.ok = false;
            break;
        }
        for (size_t b = 1; b < nb; ++b) {
            ak_rigid_shape s = ak_rigid_body_get_desc(m, b).shape;
            ak_vec3 ax = ak_quat_rotate(q[b], ak_vec3_make(0.0f, s.half_height, 0.0f));
            res.lowest = ak_minf(res.lowest, ak_minf(x[b].y - ax.y, x[b].y + ax.y) - s.radius);
        }
        for (size_t k = 0; k < nj; ++k) {
            float gap, excess;
            ak_rigid_joint_error(m, k, (ak_vec3_cspan){x, nb}, (ak_quat_cspan){q, nb}, &gap,
                                 &excess);
            res.worst_gap = ak_maxf(res.worst_gap, gap);
        }
        ak_rigid_ragdoll_pose(sk, (ak_rigid_ragdoll_bone_cspan){bones, n}, root,
                              (ak_vec3_cspan){x, nb}, (ak_quat_cspan){q, nb},
                              (ak_transform_cspan){pose, n}, (ak_transform_span){back, n});
        for (size_t i = 0; i < n; ++i)
            res.worst_limit_deg =
                ak_maxf(res.worst_limit_deg, ak_degrees(limit_excess(sk, i, back[i])));
        ak_scene_world_matrices(scene, (ak_transform_cspan){back, n}, (ak_mat4_span){world, n});
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 16; ++c) res.finite = res.finite && ak_finitef(world[i].m[c]);
    }
done:
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
    free(pose), free(prev), free(back), free(world), free(bodies), free(joints), free(bones);
    free(x), free(v), free(w), free(q);
    ak_scene_destroy(scene);
    return res;
}

static void check_drop(drop_result r) {
    AK_CHECK(r.ok);
    AK_CHECK_MSG(r.worst_limit_deg <= 2.0f, "a joint left its limits by %g deg", r.worst_limit_deg);
    AK_CHECK_MSG(r.lowest > -0.02f, "a body reached %g m below the ground", -r.lowest);
    AK_CHECK_MSG(r.worst_gap < 0.01f, "joint gap %g m", r.worst_gap);
    AK_CHECK(r.finite);
}

AK_TEST(humanoid_ragdoll_from_rest) { check_drop(drop(false, 1.5f)); }
AK_TEST(humanoid_ragdoll_from_walk) { check_drop(drop(true, 1.5f)); }

int main(void) {
    AK_RUN_SLOW(humanoid_ragdoll_from_rest);
    AK_RUN(humanoid_ragdoll_from_walk);
    return ak_test_finish();
}
