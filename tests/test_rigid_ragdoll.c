/* Ragdolls dropped onto the ground: builtin:humanoid (typed joints, capsules sized from its
 * bones, or fitted to its skin) and CesiumMan (a glTF: free joints coned by free_cone_angle,
 * capsules fitted to its skin), each started from its walk clip's pose with the velocities of a
 * finite difference of two sampled poses. Checked against the skeleton, not the solver: every
 * written-back joint stays within the skeleton's own limits (ak_skeleton_joint_within_limits) and,
 * for free joints, its bone within the cone of its rest direction, within 2 degrees; no body goes
 * through the ground; the joints hold together; the start velocity of each joint's anchor is
 * the finite difference of the joint's world positions; and the pose read back skins (LBS, on
 * the skinned mesh) to finite vertices that stay above the ground within 3 cm (capsules fitted
 * to the skin: only the mesh's bulge beyond them may sink). CesiumMan absent -> SKIP. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

#include "ak_test.h"
#include "rigid/rigid_impl.h"
#include "tasks.h"

#define CESIUM "gltf/CesiumMan/glTF-Binary/CesiumMan.glb"

typedef struct drop_opts {
    bool animated; /* start from the first clip at 30% of its length, with velocities */
    float seconds;
    bool skin;  /* fit the capsules to the first skinned mesh */
    float cone; /* free_cone_angle (rad) */
    float lift; /* metres above the ground */
} drop_opts;

typedef struct drop_result {
    bool ok;
    float worst_limit_deg; /* the largest tolerance a joint needed beyond 2 degrees, else 0 */
    float worst_cone_deg;  /* free joints: largest swing of a bone from its rest direction */
    float start_cone_deg;  /* the same in the start pose */
    float lowest;          /* lowest point of any capsule (m) */
    float worst_gap;       /* largest distance between a joint's anchors (m) */
    float worst_velocity;  /* largest start-velocity error of an anchor (m/s) */
    float max_speed;       /* the anchors' largest start speed (m/s) */
    float mass;            /* kg, the whole ragdoll */
    float min_radius, max_radius; /* of the capsules */
    float lowest_vertex;          /* lowest skinned vertex at the end (m) */
    size_t bodies, skinned_vertices;
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

/* Swing (degrees) of free joint i's bone from its rest direction: the direction to the mean of
 * its children's rest offsets, in the joint's rest frame, against the same turned by the local
 * rotation relative to rest (the skeleton's measure). -1 for a joint that is not coned. */
static float cone_swing_deg(const ak_skeleton* sk, size_t i, ak_transform local) {
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    if (parents.ptr[i] < 0 || ak_skeleton_joint_type(sk, i) != AK_JOINT_FREE) return -1.0f;
    ak_vec3 dir = ak_vec3_zero();
    bool kids = false;
    for (size_t c = i + 1; c < parents.count; ++c)
        if (parents.ptr[c] == (int32_t)i)
            dir = ak_vec3_add(dir, rest.ptr[c].translation), kids = true;
    if (!kids) return -1.0f;
    dir = ak_vec3_length_sq(dir) > 1e-12f ? ak_vec3_normalize(dir) : ak_vec3_make(0, 1, 0);
    ak_quat rel = ak_quat_mul(ak_quat_conjugate(rest.ptr[i].rotation), local.rotation);
    float c = ak_clampf(ak_vec3_dot(dir, ak_vec3_normalize(ak_quat_rotate(rel, dir))), -1.0f, 1.0f);
    return ak_degrees(acosf(c));
}

static void world_positions(const ak_scene* scene, const ak_transform* pose, ak_mat4 root,
                            ak_mat4* world, size_t n) {
    ak_scene_world_matrices(scene, (ak_transform_cspan){pose, n}, (ak_mat4_span){world, n});
    for (size_t i = 0; i < n; ++i) world[i] = ak_mat4_mul(root, world[i]);
}

static drop_result drop(const ak_scene* scene, drop_opts o) {
    drop_result res = {.ok = false,
                       .lowest = INFINITY,
                       .lowest_vertex = INFINITY,
                       .finite = true,
                       .min_radius = INFINITY};
    const ak_skeleton* sk = scene->skeleton;
    size_t n = ak_skeleton_joint_count(sk);
    const ak_scene_mesh* sm = NULL;
    for (size_t i = 0; i < scene->mesh_count && !sm; ++i)
        if (scene->meshes[i].skin >= 0 && scene->meshes[i].mesh->influence_count)
            sm = &scene->meshes[i];
    const ak_mesh* mesh = sm ? sm->mesh : NULL;
    const ak_scene_skin* skin = sm ? &scene->skins[sm->skin] : NULL;
    size_t nv = mesh ? mesh->vertex_count : 0;
    ak_transform* pose = malloc(n * sizeof *pose);
    ak_transform* prev = malloc(n * sizeof *prev);
    ak_transform* back = malloc(n * sizeof *back);
    ak_mat4* world = malloc(n * sizeof *world);
    ak_mat4* world_prev = malloc(n * sizeof *world_prev);
    ak_mat4* palette = malloc((skin ? skin->joint_count : 1) * sizeof *palette);
    ak_vec3* skinned = malloc((nv ? nv : 1) * sizeof *skinned);
    size_t nb = ak_rigid_ragdoll_body_count(sk) + 1, nj = ak_rigid_ragdoll_joint_count(sk);
    ak_rigid_body_desc* bodies = calloc(nb, sizeof *bodies);
    ak_rigid_joint_desc* joints = calloc(nj + 1, sizeof *joints);
    ak_rigid_ragdoll_bone* bones = calloc(n, sizeof *bones);
    ak_vec3 *x = calloc(nb, sizeof *x), *v = calloc(nb, sizeof *v), *w = calloc(nb, sizeof *w);
    ak_quat* q = calloc(nb, sizeof *q);
    ak_rigid_model* m = NULL;
    ak_rigid_step_job job = {0};
    const float dt = 1.0f / 60.0f;
    if (!pose || !prev || !back || !world || !world_prev || !palette || !skinned || !bodies ||
        !joints || !bones || !x || !v || !w || !q)
        goto done;
    ak_scene_rest_pose(scene, (ak_transform_span){pose, n});
    ak_scene_rest_pose(scene, (ak_transform_span){prev, n});
    if (o.animated && scene->clip_count > 0) {
        const ak_clip* clip = scene->clips[0];
        float t = 0.3f * ak_clip_duration(clip);
        ak_clip_sample(clip, t, NULL, (ak_transform_span){pose, n}, (ak_f32_span){0},
                       (ak_f32_span){0});
        ak_clip_sample(clip, t - dt, NULL, (ak_transform_span){prev, n}, (ak_f32_span){0},
                       (ak_f32_span){0});
    }
    for (size_t i = 0; i < n; ++i)
        res.start_cone_deg = ak_maxf(res.start_cone_deg, cone_swing_deg(sk, i, pose[i]));
    ak_mat4 root = ak_mat4_translation(ak_vec3_make(0.0f, o.lift, 0.0f));
    bodies[0].shape.type = AK_RIGID_PLANE;
    ak_rigid_ragdoll_desc rd = {.skeleton = sk,
                                .local_pose = {pose, n},
                                .root = root,
                                .body_offset = 1,
                                .free_cone_angle = o.cone};
    if (o.animated) rd.previous_pose = (ak_transform_cspan){prev, n}, rd.previous_dt = dt;
    if (o.skin && mesh) {
        rd.skin_positions = (ak_vec3_cspan){mesh->positions, nv};
        rd.skin_joints = (ak_u16_cspan){mesh->joints, nv * mesh->influence_count};
        rd.skin_weights = (ak_f32_cspan){mesh->weights, nv * mesh->influence_count};
        rd.skin_influence_count = mesh->influence_count;
        rd.skin_slot_joints = (ak_i32_cspan){skin->joints, skin->joint_count};
        rd.skin_inverse_binds = (ak_mat4_cspan){skin->inverse_binds, skin->joint_count};
        res.skinned_vertices = nv;
    }
    if (ak_rigid_ragdoll_build(&rd, (ak_rigid_body_desc_span){bodies + 1, nb - 1},
                               (ak_rigid_joint_desc_span){joints, nj},
                               (ak_rigid_ragdoll_bone_span){bones, n}) != AK_OK)
        goto done;
    ak_rigid_model_desc md = {.bodies = {bodies, nb}, .joints = {joints, nj}};
    if (ak_rigid_model_create(&md, NULL, &m) != AK_OK) goto done;
    res.bodies = nb - 1;
    for (size_t b = 1; b < nb; ++b) {
        res.mass += ak_rigid_body_mass(m, b);
        res.min_radius = ak_minf(res.min_radius, bodies[b].shape.radius);
        res.max_radius = ak_maxf(res.max_radius, bodies[b].shape.radius);
    }
    ak_rigid_initial_state(m, (ak_vec3_span){x, nb}, (ak_quat_span){q, nb}, (ak_vec3_span){v, nb},
                           (ak_vec3_span){w, nb});
    /* each joint's anchor moves with its body as the joint moves in the clip (central axis
     * of the bone: the anchor is the joint itself) */
    world_positions(scene, pose, root, world, n);
    world_positions(scene, prev, root, world_prev, n);
    for (size_t i = 0; i < n; ++i) {
        int b = bones[i].body;
        if (b < 0) continue;
        ak_vec3 p = ak_mat4_get_translation(world[i]);
        ak_vec3 fd =
            ak_vec3_scale(ak_vec3_sub(p, ak_mat4_get_translation(world_prev[i])), 1.0f / dt);
        ak_vec3 va = ak_vec3_add(v[b], ak_vec3_cross(w[b], ak_vec3_sub(p, x[b])));
        res.worst_velocity = ak_maxf(res.worst_velocity, ak_vec3_distance(va, fd));
        res.max_speed = ak_maxf(res.max_speed, ak_vec3_length(fd));
    }
    job = (ak_rigid_step_job){.model = m,
                              .dt = dt,
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
    for (int f = 0; f < (int)(o.seconds * 60.0f); ++f) {
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
        for (size_t i = 0; i < n; ++i) {
            res.worst_limit_deg =
                ak_maxf(res.worst_limit_deg, ak_degrees(limit_excess(sk, i, back[i])));
            res.worst_cone_deg = ak_maxf(res.worst_cone_deg, cone_swing_deg(sk, i, back[i]));
        }
        world_positions(scene, back, ak_mat4_identity(), world, n);
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 16; ++c) res.finite = res.finite && ak_finitef(world[i].m[c]);
    }
    /* the last pose skinned: LBS over the mesh's own palette, then lifted by root */
    if (mesh && res.ok) {
        ak_scene_skin_palette(scene, (size_t)sm->skin, (ak_mat4_cspan){world, n},
                              (ak_mat4_span){palette, skin->joint_count});
        ak_skin_job sj = {.influence_count = mesh->influence_count,
                          .palette = {palette, skin->joint_count},
                          .positions = {mesh->positions, nv, 0},
                          .joints = {mesh->joints, nv, 0},
                          .weights = {mesh->weights, nv, 0},
                          .out_positions = {skinned, nv, 0}};
        res.finite = res.finite && ak_skin_job_run(&sj) == AK_OK;
        for (size_t i = 0; i < nv; ++i) {
            ak_vec3 p = ak_mat4_transform_point(root, skinned[i]);
            res.finite = res.finite && ak_vec3_is_finite(p);
            res.lowest_vertex = ak_minf(res.lowest_vertex, p.y);
        }
    }
done:
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
    free(pose), free(prev), free(back), free(world), free(world_prev), free(palette), free(skinned);
    free(bodies), free(joints), free(bones);
    free(x), free(v), free(w), free(q);
    return res;
}

static void check_drop(const char* name, drop_result r, float cone_deg) {
    printf("  %s: %zu bodies, %.1f kg, radii %.3f..%.3f m, lowest capsule %.4f m, lowest vertex "
           "%.3f m, "
           "limit excess %.2f deg, cone swing start %.1f max %.2f deg, gap %.4f m, anchor velocity "
           "error "
           "%.4f m/s (speeds up to %.2f)\n",
           name, r.bodies, r.mass, r.min_radius, r.max_radius, r.lowest, r.lowest_vertex,
           r.worst_limit_deg, r.start_cone_deg, r.worst_cone_deg, r.worst_gap, r.worst_velocity,
           r.max_speed);
    AK_CHECK(r.ok);
    AK_CHECK_MSG(r.worst_limit_deg <= 2.0f, "%s: a joint left its limits by %g deg", name,
                 r.worst_limit_deg);
    if (cone_deg > 0.0f)
        AK_CHECK_MSG(r.worst_cone_deg <= cone_deg + 2.0f, "%s: a free joint swung %g deg (cone %g)",
                     name, r.worst_cone_deg, cone_deg);
    AK_CHECK_MSG(r.lowest > -0.02f, "%s: a body reached %g m below the ground", name, -r.lowest);
    AK_CHECK_MSG(r.worst_gap < 0.01f, "%s: joint gap %g m", name, r.worst_gap);
    /* the anchors start as fast as the clip moves the joints; the ragdoll's velocities are the
     * backward difference over one frame, whose direction lags a joint turning at w by w dt / 2
     * (5% at 6 rad/s) */
    AK_CHECK_MSG(r.worst_velocity <= 0.05f * r.max_speed + 0.01f,
                 "%s: anchor start velocity off by %g m/s", name, r.worst_velocity);
    AK_CHECK(r.finite);
}

static ak_scene* humanoid(void) {
    ak_scene* scene = NULL;
    ak_builtin_desc bd = {.cell_size = 0.1f}; /* the coarsest skin: only the skeleton matters */
    return ak_builtin_create("humanoid", &bd, NULL, &scene) == AK_OK ? scene : NULL;
}

static void humanoid_drop(bool animated, bool skin) {
    ak_scene* scene = humanoid();
    AK_CHECK(scene != NULL);
    if (!scene) return;
    drop_result r =
        drop(scene, (drop_opts){.animated = animated, .seconds = 1.5f, .lift = 0.5f, .skin = skin});
    check_drop(animated ? (skin ? "humanoid walk, skin" : "humanoid walk") : "humanoid rest", r,
               0.0f);
    /* fitted to the skin, the capsules hold the mesh above the ground (up to the mesh's
     * bulge beyond a capsule of its mean radius) */
    if (skin)
        AK_CHECK_MSG(r.lowest_vertex > -0.03f, "a skinned vertex went %g m under the ground",
                     -r.lowest_vertex);
    ak_scene_destroy(scene);
}

AK_TEST(humanoid_ragdoll_from_rest) { humanoid_drop(false, false); }
AK_TEST(humanoid_ragdoll_from_walk) { humanoid_drop(true, false); }
AK_TEST(humanoid_ragdoll_from_walk_skin_fitted) { humanoid_drop(true, true); }

static ak_scene* cesium(void) {
    char path[4096];
    if (!ak_test_asset(path, sizeof path, CESIUM)) return NULL;
    ak_scene* scene = NULL;
    ak_diag diag;
    ak_result r = ak_io_load(path, NULL, NULL, &scene, &diag);
    AK_CHECK_MSG(r == AK_OK, "%s: %s", CESIUM, diag.message);
    return r == AK_OK ? scene : NULL;
}

/* CesiumMan from its walk, capsules from its skin, free joints coned at 100 degrees */
AK_TEST(cesium_ragdoll_from_walk_skin_fitted) {
    ak_scene* scene = cesium();
    if (!scene) AK_SKIP(CESIUM " absent (set ANIMKIT_ASSETS or put them in ../shared/assets)");
    if (!scene) return;
    const float cone = 100.0f;
    drop_result r = drop(scene, (drop_opts){.animated = true,
                                            .seconds = 1.5f,
                                            .skin = true,
                                            .cone = ak_radians(cone),
                                            .lift = 0.3f});
    check_drop("CesiumMan walk, skin", r, cone);
    AK_CHECK_MSG(r.lowest_vertex > -0.03f, "a skinned vertex went %g m under the ground",
                 -r.lowest_vertex);
    AK_CHECK_MSG(r.start_cone_deg <= cone, "the start pose is already outside the cone (%g deg)",
                 r.start_cone_deg);
    ak_scene_destroy(scene);
}

/* Powered ragdoll: builtin:humanoid in zero gravity, every joint driven each step towards its
 * walk clip's local rotation at the current time. The oracle is the clip itself: the worst
 * angle between a driven joint's written-back local rotation and the clip's. Undisturbed it
 * stays small; a kick to one forearm at t = 1 s makes it grow (several times), and it decays
 * back under the undisturbed bound by t = 2.5 s. */
typedef struct track_result {
    bool ok;
    float before, peak, after; /* degrees: [0.5, 1) s, [1, 1.5) s, [2.5, 3) s */
    float start_target_deg;    /* build's drive targets vs ak_rigid_ragdoll_drive_targets */
} track_result;

static track_result track(float compliance, float damping, float kick, int frames) {
    track_result res = {0};
    ak_scene* scene = humanoid();
    if (!scene) return res;
    const ak_skeleton* sk = scene->skeleton;
    const ak_clip* clip = scene->clip_count ? scene->clips[0] : NULL;
    size_t n = ak_skeleton_joint_count(sk), nb = ak_rigid_ragdoll_body_count(sk),
           nj = ak_rigid_ragdoll_joint_count(sk);
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_transform* pose = malloc(n * sizeof *pose);
    ak_transform* prev = malloc(n * sizeof *prev);
    ak_transform* back = malloc(n * sizeof *back);
    ak_rigid_body_desc* bodies = calloc(nb, sizeof *bodies);
    ak_rigid_joint_desc* joints = calloc(nj, sizeof *joints);
    ak_rigid_ragdoll_bone* bones = calloc(n, sizeof *bones);
    ak_quat* targets = calloc(nj, sizeof *targets);
    ak_vec3 *x = calloc(nb, sizeof *x), *v = calloc(nb, sizeof *v), *w = calloc(nb, sizeof *w);
    ak_quat* q = calloc(nb, sizeof *q);
    ak_rigid_model* m = NULL;
    ak_rigid_step_job job = {0};
    const float dt = 1.0f / 60.0f, t0 = 0.3f;
    if (!clip || !pose || !prev || !back || !bodies || !joints || !bones || !targets || !x || !v ||
        !w || !q)
        goto done;
    const float duration = ak_clip_duration(clip);
    ak_scene_rest_pose(scene, (ak_transform_span){pose, n});
    ak_scene_rest_pose(scene, (ak_transform_span){prev, n});
    ak_clip_sample(clip, t0, NULL, (ak_transform_span){pose, n}, (ak_f32_span){0},
                   (ak_f32_span){0});
    ak_clip_sample(clip, t0 - dt, NULL, (ak_transform_span){prev, n}, (ak_f32_span){0},
                   (ak_f32_span){0});
    ak_rigid_ragdoll_desc rd = {.skeleton = sk,
                                .local_pose = {pose, n},
                                .previous_pose = {prev, n},
                                .previous_dt = dt,
                                .powered = true,
                                .drive_compliance = compliance,
                                .drive_damping = damping};
    if (ak_rigid_ragdoll_build(&rd, (ak_rigid_body_desc_span){bodies, nb},
                               (ak_rigid_joint_desc_span){joints, nj},
                               (ak_rigid_ragdoll_bone_span){bones, n}) != AK_OK)
        goto done;
    if (ak_rigid_ragdoll_drive_targets(sk, (ak_rigid_ragdoll_bone_cspan){bones, n},
                                       (ak_transform_cspan){pose, n},
                                       (ak_quat_span){targets, nj}) != AK_OK)
        goto done;
    for (size_t k = 0; k < nj; ++k)
        res.start_target_deg =
            ak_maxf(res.start_target_deg,
                    ak_degrees(ak_quat_angle_between(targets[k], joints[k].drive_target)));
    ak_rigid_model_desc md = {.bodies = {bodies, nb}, .joints = {joints, nj}};
    if (ak_rigid_model_create(&md, NULL, &m) != AK_OK) goto done;
    ak_rigid_initial_state(m, (ak_vec3_span){x, nb}, (ak_quat_span){q, nb}, (ak_vec3_span){v, nb},
                           (ak_vec3_span){w, nb});
    job = (ak_rigid_step_job){.model = m,
                              .dt = dt,
                              .substeps = 20,
                              .positions = {x, nb},
                              .orientations = {q, nb},
                              .velocities = {v, nb},
                              .angular_velocities = {w, nb},
                              .drive_targets = {targets, nj}};
    size_t size = ak_rigid_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    if (!job.scratch.ptr) goto done;
    /* the kicked body: the left forearm (the elbow's capsule) */
    int kicked = -1;
    for (size_t i = 0; i < n; ++i)
        if (strcmp(ak_skeleton_joint_name(sk, i), "left_elbow") == 0) kicked = bones[i].body;
    if (kicked < 0) goto done;
    res.ok = true;
    for (int f = 1; f <= frames; ++f) {
        const float t = (float)f * dt;
        ak_clip_sample(clip, ak_time_wrap(t0 + t, duration, AK_WRAP_LOOP), NULL,
                       (ak_transform_span){pose, n}, (ak_f32_span){0}, (ak_f32_span){0});
        ak_rigid_ragdoll_drive_targets(sk, (ak_rigid_ragdoll_bone_cspan){bones, n},
                                       (ak_transform_cspan){pose, n}, (ak_quat_span){targets, nj});
        if (f == 60) v[kicked] = ak_vec3_add(v[kicked], ak_vec3_make(0.0f, 0.0f, kick));
        if (ak_rigid_step_run(&job) != AK_OK) {
            res.ok = false;
            break;
        }
        ak_rigid_ragdoll_pose(sk, (ak_rigid_ragdoll_bone_cspan){bones, n}, ak_mat4_identity(),
                              (ak_vec3_cspan){x, nb}, (ak_quat_cspan){q, nb},
                              (ak_transform_cspan){pose, n}, (ak_transform_span){back, n});
        float err = 0.0f;
        for (size_t i = 0; i < n; ++i)
            if (bones[i].body >= 0 && parents.ptr[i] >= 0)
                err = ak_maxf(
                    err, ak_degrees(ak_quat_angle_between(back[i].rotation, pose[i].rotation)));
        if (f >= 30 && f < 60) res.before = ak_maxf(res.before, err);
        if (f >= 60 && f < 90) res.peak = ak_maxf(res.peak, err);
        if (f >= 150) res.after = ak_maxf(res.after, err);
    }
done:
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
    free(pose), free(prev), free(back), free(bodies), free(joints), free(bones), free(targets);
    free(x), free(v), free(w), free(q);
    ak_scene_destroy(scene);
    return res;
}

AK_TEST(powered_ragdoll_tracks_clip_and_recovers) {
    const float bound = 3.0f; /* degrees */
    /* drives of 1e-3 rad/(N m) (1000 N m/rad), damped at 30/s; the forearm's velocity raised by
     * 20 m/s (a 1.5 kg forearm hit by a 0.5 kg ball at 60 m/s) */
    track_result r = track(1e-3f, 30.0f, 20.0f, 180);
    printf("  powered: error before the kick %.2f deg, peak %.2f, 1.5 s after %.2f; start targets "
           "%.4f deg\n",
           r.before, r.peak, r.after, r.start_target_deg);
    AK_CHECK(r.ok);
    AK_CHECK_MSG(r.start_target_deg < 0.01f, "build's targets and drive_targets differ by %g deg",
                 r.start_target_deg);
    AK_CHECK_MSG(r.before < bound, "the undisturbed ragdoll is %g deg off the clip", r.before);
    AK_CHECK_MSG(r.peak > 2.0f * r.before && r.peak > bound, "the kick moved it only %g deg",
                 r.peak);
    AK_CHECK_MSG(r.after < bound, "1.5 s after the kick it is still %g deg off the clip", r.after);
    /* control: with drives too soft to act, it does not follow the clip */
    track_result loose = track(1e3f, 0.0f, 0.0f, 45);
    printf("  nearly unpowered (compliance 1e3): error %.2f deg\n", loose.before);
    AK_CHECK_MSG(loose.before > 2.0f * bound, "an unpowered ragdoll followed the clip (%g deg)",
                 loose.before);
}

/* The step job's drive_targets replace the model's: two spheres in zero gravity joined by a
 * ball joint with a rigid drive (built at the identity) turn to a target of 90 degrees about Z
 * given only to the step; bad targets are refused. */
AK_TEST(step_drive_targets_override) {
    ak_rigid_body_desc bodies[2] = {{.shape = {.radius = 0.1f}, .position = {0, 0, 0}},
                                    {.shape = {.radius = 0.1f}, .position = {0.5f, 0, 0}}};
    ak_rigid_joint_desc joint = {.body_a = 0, .body_b = 1, .anchor = {0.25f, 0, 0}, .drive = true};
    ak_rigid_model_desc md = {.bodies = {bodies, 2}, .joints = {&joint, 1}};
    ak_rigid_model* m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    if (!m) return;
    ak_vec3 x[2], v[2], w[2];
    ak_quat q[2];
    ak_rigid_initial_state(m, (ak_vec3_span){x, 2}, (ak_quat_span){q, 2}, (ak_vec3_span){v, 2},
                           (ak_vec3_span){w, 2});
    ak_quat target = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), ak_radians(90.0f));
    ak_rigid_step_job job = {.model = m,
                             .dt = 1.0f / 60.0f,
                             .substeps = 20,
                             .positions = {x, 2},
                             .orientations = {q, 2},
                             .velocities = {v, 2},
                             .angular_velocities = {w, 2},
                             .drive_targets = {&target, 1}};
    size_t size = ak_rigid_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    AK_CHECK(job.scratch.ptr != NULL);
    if (job.scratch.ptr) {
        for (int f = 0; f < 60; ++f) AK_CHECK_EQ(ak_rigid_step_run(&job), AK_OK);
        ak_quat rel = ak_quat_mul(ak_quat_conjugate(q[0]), q[1]);
        float off = ak_degrees(ak_quat_angle_between(rel, target));
        AK_CHECK_MSG(off < 1.0f, "relative orientation %g deg from the step's target", off);
        ak_quat bad = {NAN, 0, 0, 1};
        job.drive_targets = (ak_quat_cspan){&bad, 1};
        AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_BAD_DATA);
        bad = (ak_quat){0, 0, 0, 0};
        AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_BAD_DATA);
        job.drive_targets = (ak_quat_cspan){NULL, 1};
        AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_NULL_ARG);
        joint.drive_damping = -1.0f;
        ak_rigid_model* m2 = NULL;
        AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m2), AK_ERR_BAD_ARG);
        ak_rigid_model_destroy(m2);
    }
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
}

/* A broken skin is refused with the code its header names, and nothing is half-built. */
AK_TEST(ragdoll_skin_bad_input) {
    ak_scene* scene = humanoid();
    AK_CHECK(scene != NULL);
    if (!scene) return;
    const ak_skeleton* sk = scene->skeleton;
    const ak_mesh* mesh = scene->meshes[0].mesh;
    const ak_scene_skin* skin = &scene->skins[scene->meshes[0].skin];
    size_t n = ak_skeleton_joint_count(sk), nb = ak_rigid_ragdoll_body_count(sk),
           nj = ak_rigid_ragdoll_joint_count(sk);
    size_t nv = mesh->vertex_count, k = mesh->influence_count;
    ak_transform* pose = malloc(n * sizeof *pose);
    ak_rigid_body_desc* bodies = calloc(nb, sizeof *bodies);
    ak_rigid_joint_desc* joints = calloc(nj, sizeof *joints);
    ak_rigid_ragdoll_bone* bones = calloc(n, sizeof *bones);
    ak_vec3* pos = malloc(nv * sizeof *pos);
    uint16_t* slots = malloc(nv * k * sizeof *slots);
    int32_t* slot_joints = malloc(skin->joint_count * sizeof *slot_joints);
    AK_CHECK(pose && bodies && joints && bones && pos && slots && slot_joints);
    if (pose && bodies && joints && bones && pos && slots && slot_joints) {
        ak_scene_rest_pose(scene, (ak_transform_span){pose, n});
        memcpy(pos, mesh->positions, nv * sizeof *pos);
        memcpy(slots, mesh->joints, nv * k * sizeof *slots);
        memcpy(slot_joints, skin->joints, skin->joint_count * sizeof *slot_joints);
        ak_rigid_ragdoll_desc rd = {.skeleton = sk,
                                    .local_pose = {pose, n},
                                    .skin_positions = {pos, nv},
                                    .skin_joints = {slots, nv * k},
                                    .skin_weights = {mesh->weights, nv * k},
                                    .skin_influence_count = (uint32_t)k,
                                    .skin_slot_joints = {slot_joints, skin->joint_count},
                                    .skin_inverse_binds = {skin->inverse_binds, skin->joint_count}};
        ak_rigid_body_desc_span ob = {bodies, nb};
        ak_rigid_joint_desc_span oj = {joints, nj};
        ak_rigid_ragdoll_bone_span obn = {bones, n};
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&rd, ob, oj, obn), AK_OK);
        /* a fitted capsule is no longer the radius_scale one: the skin changed something */
        ak_rigid_ragdoll_desc plain = rd;
        plain.skin_positions = (ak_vec3_cspan){0};
        plain.skin_joints = (ak_u16_cspan){0};
        plain.skin_weights = (ak_f32_cspan){0};
        plain.skin_influence_count = 0;
        plain.skin_slot_joints = (ak_i32_cspan){0};
        plain.skin_inverse_binds = (ak_mat4_cspan){0};
        ak_rigid_body_desc* plain_bodies = calloc(nb, sizeof *plain_bodies);
        AK_CHECK_EQ(
            ak_rigid_ragdoll_build(&plain, (ak_rigid_body_desc_span){plain_bodies, nb}, oj, obn),
            AK_OK);
        int differ = 0;
        for (size_t b = 0; b < nb; ++b)
            differ += bodies[b].shape.radius != plain_bodies[b].shape.radius;
        AK_CHECK_MSG(differ > 0, "the skin changed no capsule");
        free(plain_bodies);
        ak_rigid_ragdoll_desc bad = rd;
        bad.skin_influence_count = 0;
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&bad, ob, oj, obn), AK_ERR_BAD_ARG);
        bad = rd;
        bad.skin_influence_count = 9;
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&bad, ob, oj, obn), AK_ERR_BAD_ARG);
        bad = rd;
        bad.skin_weights.count = nv * k - 1;
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&bad, ob, oj, obn), AK_ERR_SPAN_SMALL);
        bad = rd;
        bad.skin_inverse_binds.ptr = NULL;
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&bad, ob, oj, obn), AK_ERR_NULL_ARG);
        bad = rd;
        bad.free_cone_angle = -1.0f;
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&bad, ob, oj, obn), AK_ERR_BAD_ARG);
        slots[nv / 2 * k] = (uint16_t)skin->joint_count; /* a slot past the skin */
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&rd, ob, oj, obn), AK_ERR_BAD_INDEX);
        slots[nv / 2 * k] = mesh->joints[nv / 2 * k];
        slot_joints[0] = (int32_t)n; /* a slot naming no joint */
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&rd, ob, oj, obn), AK_ERR_BAD_INDEX);
        slot_joints[0] = skin->joints[0];
        pos[nv - 1].y = NAN;
        AK_CHECK_EQ(ak_rigid_ragdoll_build(&rd, ob, oj, obn), AK_ERR_BAD_DATA);
    }
    free(pose), free(bodies), free(joints), free(bones), free(pos), free(slots), free(slot_joints);
    ak_scene_destroy(scene);
}

/* thread_count: the joint sweeps after the contacts run chain by chain (each ragdoll is one),
 * the chains shared out over the threads. Four builtin:humanoid ragdolls, each turned and lifted
 * differently, fall onto the ground for 0.6 s (they land and tumble: joints, contacts and
 * limits all act) with 1, 2 and 3 threads: the states must be equal to the bit, the ragdolls
 * must have reached the ground, and their joints must still hold (anchors within 5 mm). */
static bool threads_run(uint32_t threads, size_t nb, const ak_rigid_model* m, ak_vec3* x,
                        ak_quat* q, ak_vec3* v, ak_vec3* w, float* timers) {
    ak_rigid_initial_state(m, (ak_vec3_span){x, nb}, (ak_quat_span){q, nb}, (ak_vec3_span){v, nb},
                           (ak_vec3_span){w, nb});
    for (size_t i = 0; i < nb; ++i) timers[i] = 0.0f;
    ak_rigid_step_job job = {.model = m,
                             .dt = 1.0f / 60.0f,
                             .substeps = 10,
                             .gravity = ak_vec3_make(0.0f, -9.81f, 0.0f),
                             .thread_count = threads,
                             .positions = {x, nb},
                             .orientations = {q, nb},
                             .velocities = {v, nb},
                             .angular_velocities = {w, nb},
                             .sleep_timers = {timers, nb}};
    size_t bytes = ak_rigid_step_scratch_size(&job);
    uint8_t* scratch = malloc(bytes);
    if (!scratch) return false;
    job.scratch = (ak_u8_span){scratch, bytes};
    bool ok = true;
    for (int s = 0; s < 36 && ok; ++s) ok = ak_rigid_step_run(&job) == AK_OK;
    free(scratch);
    return ok;
}

/* Ragdoll r of a row (bodies from 1 + r * per, joints from r * pj, collision group r + 1):
 * tipped over by 20 + 25 r degrees about a different axis each, 0.3 + 0.2 r m up, at x = xr. */
static ak_result tipped_ragdoll(const ak_skeleton* sk, const ak_transform* pose, size_t n, int r,
                                float xr, ak_rigid_body_desc* bodies, size_t per,
                                ak_rigid_joint_desc* joints, size_t pj,
                                ak_rigid_ragdoll_bone* bones) {
    ak_vec3 axis = ak_vec3_make(1.0f, 0.3f * (float)r, 0.5f * (float)(r % 3));
    ak_mat4 root = ak_mat4_mul(
        ak_mat4_translation(ak_vec3_make(xr, 0.3f + 0.2f * (float)r, 0.0f)),
        ak_mat4_from_quat(
            ak_quat_from_axis_angle(axis, (20.0f + 25.0f * (float)r) * 3.14159265f / 180.0f)));
    ak_rigid_ragdoll_desc rd = {.skeleton = sk,
                                .local_pose = {pose, n},
                                .root = root,
                                .body_offset = (uint32_t)(1 + (size_t)r * per),
                                .collision_group = (uint32_t)r + 1};
    return ak_rigid_ragdoll_build(&rd, (ak_rigid_body_desc_span){bodies + 1 + (size_t)r * per, per},
                                  (ak_rigid_joint_desc_span){joints + (size_t)r * pj, pj},
                                  (ak_rigid_ragdoll_bone_span){bones, n});
}

AK_TEST(ragdolls_bit_identical_for_any_thread_count) {
    enum { RAGDOLLS = 4 };
    ak_scene* scene = NULL;
    ak_builtin_desc bd = {.cell_size = 0.1f};
    AK_CHECK_EQ(ak_builtin_create("humanoid", &bd, NULL, &scene), AK_OK);
    if (!scene) return;
    const ak_skeleton* sk = scene->skeleton;
    size_t n = ak_skeleton_joint_count(sk), per = ak_rigid_ragdoll_body_count(sk),
           pj = ak_rigid_ragdoll_joint_count(sk);
    size_t nb = 1 + RAGDOLLS * per, nj = RAGDOLLS * pj;
    ak_transform* pose = malloc(n * sizeof *pose);
    ak_rigid_ragdoll_bone* bones = malloc(n * sizeof *bones);
    ak_rigid_body_desc* bodies = calloc(nb, sizeof *bodies);
    ak_rigid_joint_desc* joints = calloc(nj, sizeof *joints);
    ak_vec3* st[3][3] = {{0}};
    ak_quat* sq[3] = {0};
    float* timers = malloc(nb * sizeof *timers);
    bool alloc_ok = pose && bones && bodies && joints && timers;
    for (int t = 0; t < 3; ++t) {
        for (int k = 0; k < 3; ++k)
            alloc_ok = alloc_ok && (st[t][k] = malloc(nb * sizeof(ak_vec3)));
        alloc_ok = alloc_ok && (sq[t] = malloc(nb * sizeof(ak_quat)));
    }
    ak_rigid_model* m = NULL;
    AK_CHECK(alloc_ok);
    if (!alloc_ok) goto done;
    ak_scene_rest_pose(scene, (ak_transform_span){pose, n});
    bodies[0].shape.type = AK_RIGID_PLANE;
    for (int r = 0; r < RAGDOLLS; ++r)
        AK_CHECK_EQ(tipped_ragdoll(sk, pose, n, r, 2.5f * (float)r, bodies, per, joints, pj, bones),
                    AK_OK);
    ak_rigid_model_desc md = {.bodies = {bodies, nb}, .joints = {joints, nj}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    if (!m) goto done;
    for (int t = 0; t < 3; ++t)
        AK_CHECK(threads_run((uint32_t)t + 1, nb, m, st[t][0], sq[t], st[t][1], st[t][2], timers));
    for (int t = 1; t < 3; ++t) {
        for (int k = 0; k < 3; ++k)
            AK_CHECK_MSG(memcmp(st[0][k], st[t][k], nb * sizeof(ak_vec3)) == 0,
                         "%d threads: state %d differs from one thread's", t + 1, k);
        AK_CHECK_MSG(memcmp(sq[0], sq[t], nb * sizeof(ak_quat)) == 0,
                     "%d threads: orientations differ from one thread's", t + 1);
    }
    /* every ragdoll came down to the ground (its lowest capsule centre under 0.25 m) */
    for (int r = 0; r < RAGDOLLS; ++r) {
        float low = INFINITY;
        for (size_t b = 0; b < per; ++b) low = ak_minf(low, st[0][0][1 + r * per + b].y);
        AK_CHECK_MSG(low < 0.25f, "ragdoll %d: lowest body at %g m", r, low);
    }
    float worst = 0.0f;
    for (size_t k = 0; k < nj; ++k) {
        float gap = 0.0f, excess = 0.0f;
        AK_CHECK_EQ(ak_rigid_joint_error(m, k, (ak_vec3_cspan){st[0][0], nb},
                                         (ak_quat_cspan){sq[0], nb}, &gap, &excess),
                    AK_OK);
        worst = ak_maxf(worst, gap);
    }
    AK_CHECK_MSG(worst < 5e-3f, "a joint's anchors are %g m apart", worst);
done:
    ak_rigid_model_destroy(m);
    for (int t = 0; t < 3; ++t) {
        for (int k = 0; k < 3; ++k) free(st[t][k]);
        free(sq[t]);
    }
    free(pose), free(bones), free(bodies), free(joints), free(timers);
    ak_scene_destroy(scene);
}

/* Islands: the bodies joined by the step's contact pairs and by joints are solved island by
 * island (on the worker team when thread_count > 1), with the same numbers as one solve of
 * the whole world (akp_rigid_step_run with islands off: the solver as it was before them).
 * The world mixes what an island holds: the ground, four humanoid ragdolls (the first two
 * overlap, so they collide and make one island of two joint chains), a stack of three boxes
 * (cached flat contacts), spheres on the ground and on the stack (their narrow phase runs each
 * substep), a capsule swinging on a ball joint from a static box (a joint to a static body),
 * a box dropped onto that static box, and a box asleep at the start that a sphere wakes. 36 steps
 * with 1, 2 and 3 threads against the one-island run, state, sleep timers, contact counts and
 * deepest penetration equal to the bit at every step; once more with max_contacts too small for the
 * islands' contact regions (the step falls back to one island, and still drops the same). The
 * two-thread run must also have used the team once per solve of a step (the islands' one
 * parallel section), not once per substep (360) as the chain sweeps of the one-island path do: a
 * step is solved once, or again (at most 3 times in all) when an impact sets a body moving past
 * its pairs' margins (the two ragdolls falling into each other here). And with
 * contacts_after_joints and 2 contact_iterations, two threads against the one-island run. */
enum { ISL_STEPS = 36 };

typedef struct isl_run {
    ak_vec3 *x, *v, *w;
    ak_quat* q;
    float* timers;
    uint32_t contacts[ISL_STEPS], dropped[ISL_STEPS];
    float pen[ISL_STEPS];
} isl_run;

static bool isl_step_all(const ak_rigid_model* m, size_t nb, uint32_t threads, bool islands,
                         const float* timers0, isl_run* out) {
    ak_rigid_initial_state(m, (ak_vec3_span){out->x, nb}, (ak_quat_span){out->q, nb},
                           (ak_vec3_span){out->v, nb}, (ak_vec3_span){out->w, nb});
    memcpy(out->timers, timers0, nb * sizeof *timers0);
    float pen = 0.0f;
    uint32_t contacts = 0, dropped = 0;
    ak_rigid_step_job job = {.model = m,
                             .dt = 1.0f / 60.0f,
                             .substeps = 10,
                             .gravity = ak_vec3_make(0.0f, -9.81f, 0.0f),
                             .thread_count = threads,
                             .positions = {out->x, nb},
                             .orientations = {out->q, nb},
                             .velocities = {out->v, nb},
                             .angular_velocities = {out->w, nb},
                             .sleep_timers = {out->timers, nb},
                             .out_max_penetration = &pen,
                             .out_contact_count = &contacts,
                             .out_dropped_contacts = &dropped};
    size_t bytes = ak_rigid_step_scratch_size(&job);
    uint8_t* scratch = malloc(bytes);
    if (!scratch) return false;
    job.scratch = (ak_u8_span){scratch, bytes};
    bool ok = true;
    for (int s = 0; s < ISL_STEPS && ok; ++s) {
        ok = akp_rigid_step_run(&job, islands) == AK_OK;
        out->contacts[s] = contacts, out->dropped[s] = dropped, out->pen[s] = pen;
    }
    free(scratch);
    return ok;
}

static bool isl_same(const isl_run* a, const isl_run* b, size_t nb) {
    return memcmp(a->x, b->x, nb * sizeof(ak_vec3)) == 0 &&
           memcmp(a->v, b->v, nb * sizeof(ak_vec3)) == 0 &&
           memcmp(a->w, b->w, nb * sizeof(ak_vec3)) == 0 &&
           memcmp(a->q, b->q, nb * sizeof(ak_quat)) == 0 &&
           memcmp(a->timers, b->timers, nb * sizeof(float)) == 0 &&
           memcmp(a->contacts, b->contacts, sizeof a->contacts) == 0 &&
           memcmp(a->dropped, b->dropped, sizeof a->dropped) == 0 &&
           memcmp(a->pen, b->pen, sizeof a->pen) == 0;
}

AK_TEST(islands_bit_identical_for_any_thread_count) {
    enum { RAGDOLLS = 4, EXTRA = 11, RUNS = 4 };
    ak_scene* scene = NULL;
    ak_builtin_desc bd = {.cell_size = 0.1f};
    AK_CHECK_EQ(ak_builtin_create("humanoid", &bd, NULL, &scene), AK_OK);
    if (!scene) return;
    const ak_skeleton* sk = scene->skeleton;
    size_t n = ak_skeleton_joint_count(sk), per = ak_rigid_ragdoll_body_count(sk),
           pj = ak_rigid_ragdoll_joint_count(sk);
    size_t nb = 1 + RAGDOLLS * per + EXTRA, nj = RAGDOLLS * pj + 1;
    ak_transform* pose = malloc(n * sizeof *pose);
    ak_rigid_ragdoll_bone* bones = malloc(n * sizeof *bones);
    ak_rigid_body_desc* bodies = calloc(nb, sizeof *bodies);
    ak_rigid_joint_desc* joints = calloc(nj, sizeof *joints);
    float* timers0 = calloc(nb, sizeof *timers0);
    isl_run runs[RUNS];
    memset(runs, 0, sizeof runs);
    bool alloc_ok = pose && bones && bodies && joints && timers0;
    for (int r = 0; r < RUNS; ++r) {
        runs[r].x = malloc(nb * sizeof(ak_vec3)), runs[r].v = malloc(nb * sizeof(ak_vec3));
        runs[r].w = malloc(nb * sizeof(ak_vec3)), runs[r].q = malloc(nb * sizeof(ak_quat));
        runs[r].timers = malloc(nb * sizeof(float));
        alloc_ok = alloc_ok && runs[r].x && runs[r].v && runs[r].w && runs[r].q && runs[r].timers;
    }
    ak_rigid_model* m = NULL;
    ak_rigid_model* small = NULL;
    ak_rigid_model* after = NULL;
    AK_CHECK(alloc_ok);
    if (!alloc_ok) goto done;
    ak_scene_rest_pose(scene, (ak_transform_span){pose, n});
    bodies[0].shape.type = AK_RIGID_PLANE;
    for (int r = 0; r < RAGDOLLS; ++r) {
        /* ragdolls 0 and 1 side by side 0.3 m apart: they fall into each other */
        float xr = r == 0 ? 0.0f : (r == 1 ? 0.3f : 2.5f * (float)r);
        AK_CHECK_EQ(tipped_ragdoll(sk, pose, n, r, xr, bodies, per, joints, pj, bones), AK_OK);
    }
    ak_rigid_body_desc* e = bodies + 1 + RAGDOLLS * per;
    size_t e0 = 1 + RAGDOLLS * per;
    for (int k = 0; k < 3; ++k) /* a stack of three boxes, the top one turned a little */
        e[k] = (ak_rigid_body_desc){
            .shape = {.type = AK_RIGID_BOX, .half_extents = {0.25f, 0.25f, 0.25f}},
            .position = {-3.0f, 0.25f + 0.5f * (float)k, 0.0f},
            .orientation = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.2f * (float)k)};
    e[3] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_SPHERE, .radius = 0.1f},
                                .position = {-3.05f, 1.45f, 0.02f},
                                .restitution = 0.3f};
    e[4] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_SPHERE, .radius = 0.15f},
                                .position = {-5.0f, 0.4f, 0.0f},
                                .velocity = {1.0f, 0, 0}};
    e[5] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_SPHERE, .radius = 0.15f},
                                .position = {-4.6f, 0.15f, 0.0f}};
    e[6] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_BOX, .half_extents = {0.2f, 0.2f, 0.2f}},
                                .position = {-8.0f, 2.0f, 0.0f},
                                .orientation = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.4f),
                                .is_static = true};
    e[7] = (ak_rigid_body_desc){
        .shape = {.type = AK_RIGID_CAPSULE, .radius = 0.1f, .half_height = 0.3f},
        .position = {-7.4f, 2.0f, 0.0f},
        .orientation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5707963f)};
    /* asleep at the start, under the capsule's swing: woken when something touches it */
    e[8] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_BOX, .half_extents = {0.3f, 0.3f, 0.3f}},
                                .position = {-8.0f, 0.3f, 0.0f}};
    e[9] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_SPHERE, .radius = 0.2f},
                                .position = {-8.1f, 1.2f, 0.05f}};
    /* a box dropped onto the (turned) static box */
    e[10] =
        (ak_rigid_body_desc){.shape = {.type = AK_RIGID_BOX, .half_extents = {0.1f, 0.1f, 0.1f}},
                             .position = {-8.05f, 2.45f, 0.05f}};
    timers0[e0 + 8] = 10.0f;
    joints[nj - 1] = (ak_rigid_joint_desc){.type = AK_RIGID_JOINT_BALL,
                                           .body_a = (uint32_t)(e0 + 6),
                                           .body_b = (uint32_t)(e0 + 7),
                                           .anchor = {-7.8f, 2.0f, 0.0f}};
    ak_rigid_model_desc md = {.bodies = {bodies, nb}, .joints = {joints, nj}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    if (!m) goto done;
    AK_CHECK(isl_step_all(m, nb, 1, false, timers0, &runs[0]));
    uint64_t team0 = 0, fresh0 = 0, team1 = 0, fresh1 = 0;
    for (int t = 1; t <= 3; ++t) {
        if (t == 2) akp_tasks_stats(&team0, &fresh0);
        AK_CHECK(isl_step_all(m, nb, (uint32_t)t, true, timers0, &runs[t]));
        if (t == 2) akp_tasks_stats(&team1, &fresh1);
        AK_CHECK_MSG(isl_same(&runs[0], &runs[t], nb),
                     "islands, %d thread(s): the state differs from the one-island solve's", t);
    }
    AK_CHECK_MSG((team1 - team0) + (fresh1 - fresh0) >= ISL_STEPS &&
                     (team1 - team0) + (fresh1 - fresh0) <= 3 * ISL_STEPS,
                 "2 threads: %llu parallel sections in %d steps",
                 (unsigned long long)((team1 - team0) + (fresh1 - fresh0)), ISL_STEPS);
    /* the world did something: the ragdolls reached the ground, the sleeper was woken */
    for (int r = 0; r < RAGDOLLS; ++r) {
        float low = INFINITY;
        for (size_t b = 0; b < per; ++b) low = ak_minf(low, runs[1].x[1 + r * per + b].y);
        AK_CHECK_MSG(low < 0.25f, "ragdoll %d: lowest body at %g m", r, low);
    }
    AK_CHECK_MSG(runs[1].timers[e0 + 8] < 0.5f, "the sleeping box was not woken (timer %g)",
                 runs[1].timers[e0 + 8]);
    /* too small a contact buffer: the islands' regions do not fit, one island it is */
    md.max_contacts = 40;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &small), AK_OK);
    if (!small) goto done;
    AK_CHECK(isl_step_all(small, nb, 1, false, timers0, &runs[0]));
    AK_CHECK(isl_step_all(small, nb, 2, true, timers0, &runs[2]));
    AK_CHECK_MSG(isl_same(&runs[0], &runs[2], nb), "max_contacts 40: the fallback differs");
    AK_CHECK_MSG(runs[0].dropped[ISL_STEPS - 1] > 0, "max_contacts 40 dropped nothing");
    /* contacts_after_joints and contact_iterations: their passes over each island's contacts
     * give the same bits too */
    md.max_contacts = 0;
    md.contacts_after_joints = true;
    md.contact_iterations = 2;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &after), AK_OK);
    if (!after) goto done;
    AK_CHECK(isl_step_all(after, nb, 1, false, timers0, &runs[0]));
    AK_CHECK(isl_step_all(after, nb, 2, true, timers0, &runs[2]));
    AK_CHECK_MSG(isl_same(&runs[0], &runs[2], nb), "contacts after joints, 2 iterations: the islands differ");
    AK_CHECK_MSG(!isl_same(&runs[1], &runs[2], nb), "contacts after joints, 2 iterations: nothing changed");
done:
    ak_rigid_model_destroy(after);
    ak_rigid_model_destroy(small);
    ak_rigid_model_destroy(m);
    for (int r = 0; r < RUNS; ++r)
        free(runs[r].x), free(runs[r].v), free(runs[r].w), free(runs[r].q), free(runs[r].timers);
    free(pose), free(bones), free(bodies), free(joints), free(timers0);
    ak_scene_destroy(scene);
}

int main(void) {
    AK_RUN_SLOW(humanoid_ragdoll_from_rest);
    AK_RUN(humanoid_ragdoll_from_walk);
    AK_RUN_SLOW(humanoid_ragdoll_from_walk_skin_fitted);
    AK_RUN(cesium_ragdoll_from_walk_skin_fitted);
    AK_RUN(ragdoll_skin_bad_input);
    AK_RUN(powered_ragdoll_tracks_clip_and_recovers);
    AK_RUN(step_drive_targets_override);
    AK_RUN(ragdolls_bit_identical_for_any_thread_count);
    AK_RUN(islands_bit_identical_for_any_thread_count);
    return ak_test_finish();
}
