/* Retargeting real motion capture: CMU BVH (../shared/assets/bvh) onto builtin:humanoid and
 * onto CesiumMan (a map written here: its joint names follow no rig convention). Checks:
 * every baked value finite, the target's bone lengths kept at every frame, and foot slide
 * during the source's foot contacts (detected here on the source, independently) far lower
 * with the clean-up than without. Then `animkit retarget` (glb, gif, bad map files). */
#include <animkit/animkit.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ak_test.h"

/* Documented bound (docs/retarget.md): with the clean-up, the target feet slide less than
 * 2% of the slide without it, summed over the frames where the source foot is in contact. */
#define SLIDE_RATIO_BOUND 0.02

static const char* const k_cesium_map[][2] = {
    {"Skeleton_torso_joint_1", "Hips"},      {"leg_joint_L_1", "LeftUpLeg"},
    {"leg_joint_L_2", "LeftLeg"},            {"leg_joint_L_3", "LeftFoot"},
    {"leg_joint_R_1", "RightUpLeg"},         {"leg_joint_R_2", "RightLeg"},
    {"leg_joint_R_3", "RightFoot"},          {"Skeleton_torso_joint_2", "Spine"},
    {"torso_joint_3", "Spine1"},             {"Skeleton_neck_joint_1", "Neck"},
    {"Skeleton_neck_joint_2", "Head"},       {"Skeleton_arm_joint_L__4_", "LeftArm"},
    {"Skeleton_arm_joint_L__3_", "LeftForeArm"}, {"Skeleton_arm_joint_L__2_", "LeftHand"},
    {"Skeleton_arm_joint_R", "RightArm"},    {"Skeleton_arm_joint_R__2_", "RightForeArm"},
    {"Skeleton_arm_joint_R__3_", "RightHand"},
};

typedef struct run_result {
    bool finite;
    double bone_error;  /* largest |bone length - rest length| / rest length */
    double slide;       /* target foot horizontal travel over source contact frame pairs */
    size_t contact_pairs;
    double floor_gap;   /* lowest target ankle over the clip minus its lowest at rest (m) */
    double arm_angle;   /* largest angle (degrees) between the target's and the source's
                           left upper-arm directions in model space over the clip */
} run_result;

static ak_vec3 joint_pos(const ak_mat4* m) { return ak_mat4_get_translation(*m); }

/* Retarget, then measure on the baked clip. feet: target joint of the left/right foot and
 * the source joints they follow. */
static run_result run(const ak_scene* src, const ak_scene* dst, const int32_t* map, bool clean, const int* tfeet,
                      const int* sfeet, const int* tarm, const int* sarm, ak_retarget_stats* st) {
    run_result out = {.finite = false};
    const ak_skeleton *ss = src->skeleton, *ts = dst->skeleton;
    size_t ns = ak_skeleton_joint_count(ss), nt = ak_skeleton_joint_count(ts);
    ak_retarget_desc d = {.source = ss, .clip = src->clips[0], .target = ts,
                          .source_of_target = {map, map ? nt : 0}, .skip_foot_contacts = !clean};
    ak_clip* clip = NULL;
    ak_diag diag;
    ak_result r = ak_retarget_clip(&d, NULL, &clip, st, &diag);
    AK_CHECK_MSG(r == AK_OK, "retarget: %s", diag.message);
    if (r != AK_OK) return out;
    ak_transform *ls = malloc(ns * sizeof *ls), *lt = malloc(nt * sizeof *lt);
    ak_mat4 *ms = malloc(ns * sizeof *ms), *mt = malloc(nt * sizeof *mt);
    ak_mat4* mt_rest = malloc(nt * sizeof *mt_rest);
    ak_skeleton_local_to_model(ts, ak_skeleton_rest_pose(ts), (ak_mat4_span){mt_rest, nt});
    ak_i32_cspan tp = ak_skeleton_parents(ts);
    /* source contact detection (same rule and thresholds as documented, in double) */
    size_t nf = st->frame_count;
    double* sy = malloc(2 * nf * sizeof(double));
    double* sxz = malloc(4 * nf * sizeof(double));
    double* txz = malloc(4 * nf * sizeof(double));
    double leg = 0;
    ak_mat4* ms_rest = malloc(ns * sizeof *ms_rest);
    ak_skeleton_local_to_model(ss, ak_skeleton_rest_pose(ss), (ak_mat4_span){ms_rest, ns});
    {
        int foot = sfeet[0], knee = ak_skeleton_parents(ss).ptr[foot], hip = ak_skeleton_parents(ss).ptr[knee];
        leg = ak_vec3_length(ak_vec3_sub(joint_pos(&ms_rest[knee]), joint_pos(&ms_rest[hip]))) +
              ak_vec3_length(ak_vec3_sub(joint_pos(&ms_rest[foot]), joint_pos(&ms_rest[knee])));
    }
    out.finite = true;
    double rest_floor = fmin(joint_pos(&mt_rest[tfeet[0]]).y, joint_pos(&mt_rest[tfeet[1]]).y), floor = 1e30;
    float dur = ak_clip_duration(src->clips[0]);
    for (size_t f = 0; f < nf; ++f) {
        float t = (float)f / 30.0f;
        if (t > dur || f + 1 == nf) t = dur;
        memcpy(ls, ak_skeleton_rest_pose(ss).ptr, ns * sizeof *ls);
        ak_clip_sample(src->clips[0], t, NULL, (ak_transform_span){ls, ns}, (ak_f32_span){0}, (ak_f32_span){0});
        ak_skeleton_local_to_model(ss, (ak_transform_cspan){ls, ns}, (ak_mat4_span){ms, ns});
        memcpy(lt, ak_skeleton_rest_pose(ts).ptr, nt * sizeof *lt);
        ak_clip_sample(clip, (float)f / 30.0f, NULL, (ak_transform_span){lt, nt}, (ak_f32_span){0}, (ak_f32_span){0});
        ak_skeleton_local_to_model(ts, (ak_transform_cspan){lt, nt}, (ak_mat4_span){mt, nt});
        if (!ak_pose_is_finite((ak_transform_cspan){lt, nt})) out.finite = false;
        for (size_t j = 1; j < nt; ++j) {
            if (tp.ptr[j] < 0 || (int32_t)j == st->root_joint) continue; /* the root moves: not a bone */
            double rest = ak_vec3_length(ak_vec3_sub(joint_pos(&mt_rest[j]), joint_pos(&mt_rest[tp.ptr[j]])));
            double now = ak_vec3_length(ak_vec3_sub(joint_pos(&mt[j]), joint_pos(&mt[tp.ptr[j]])));
            if (rest > 1e-6) out.bone_error = fmax(out.bone_error, fabs(now - rest) / rest);
        }
        {
            ak_vec3 a = ak_vec3_sub(joint_pos(&mt[tarm[1]]), joint_pos(&mt[tarm[0]]));
            ak_vec3 b = ak_vec3_sub(joint_pos(&ms[sarm[1]]), joint_pos(&ms[sarm[0]]));
            double c = ak_vec3_dot(a, b) / ((double)ak_vec3_length(a) * (double)ak_vec3_length(b));
            out.arm_angle = fmax(out.arm_angle, acos(fmax(-1.0, fmin(1.0, c))) * (180.0 / 3.14159265358979323846));
        }
        for (int s = 0; s < 2; ++s) {
            ak_vec3 p = joint_pos(&ms[sfeet[s]]), q = joint_pos(&mt[tfeet[s]]);
            floor = fmin(floor, q.y);
            sy[2 * f + (size_t)s] = p.y;
            sxz[4 * f + 2 * (size_t)s] = p.x, sxz[4 * f + 2 * (size_t)s + 1] = p.z;
            txz[4 * f + 2 * (size_t)s] = q.x, txz[4 * f + 2 * (size_t)s + 1] = q.z;
        }
    }
    for (int s = 0; s < 2; ++s) {
        double floor_y = 1e30;
        for (size_t f = 0; f < nf; ++f) floor_y = fmin(floor_y, sy[2 * f + (size_t)s]);
        bool prev = false;
        for (size_t f = 0; f < nf; ++f) {
            size_t a = f ? f - 1 : f, b = f + 1 < nf ? f + 1 : f;
            double dx = sxz[4 * b + 2 * (size_t)s] - sxz[4 * a + 2 * (size_t)s];
            double dz = sxz[4 * b + 2 * (size_t)s + 1] - sxz[4 * a + 2 * (size_t)s + 1];
            double speed = b > a ? sqrt(dx * dx + dz * dz) * 30.0 / (double)(b - a) : 0.0;
            bool c = sy[2 * f + (size_t)s] - floor_y < 0.08 * leg && speed < 0.6 * leg;
            if (c && prev) {
                double ex = txz[4 * f + 2 * (size_t)s] - txz[4 * (f - 1) + 2 * (size_t)s];
                double ez = txz[4 * f + 2 * (size_t)s + 1] - txz[4 * (f - 1) + 2 * (size_t)s + 1];
                out.slide += sqrt(ex * ex + ez * ez);
                ++out.contact_pairs;
            }
            prev = c;
        }
    }
    out.floor_gap = floor - rest_floor;
    free(ls), free(lt), free(ms), free(mt), free(mt_rest), free(sy), free(sxz), free(txz), free(ms_rest);
    ak_clip_destroy(clip);
    return out;
}

/* tl, tr: the target's ankles; tua, tla: its left upper arm and the joint below (elbow). */
static void check_target(const char* what, const ak_scene* src, const ak_scene* dst, const int32_t* map,
                         const char* tl, const char* tr, const char* tua, const char* tla) {
    int tfeet[2] = {ak_skeleton_find_joint(dst->skeleton, tl), ak_skeleton_find_joint(dst->skeleton, tr)};
    int sfeet[2] = {ak_skeleton_find_joint(src->skeleton, "LeftFoot"), ak_skeleton_find_joint(src->skeleton, "RightFoot")};
    int tarm[2] = {ak_skeleton_find_joint(dst->skeleton, tua), ak_skeleton_find_joint(dst->skeleton, tla)};
    int sarm[2] = {ak_skeleton_find_joint(src->skeleton, "LeftArm"), ak_skeleton_find_joint(src->skeleton, "LeftForeArm")};
    AK_CHECK(tfeet[0] >= 0 && tfeet[1] >= 0 && sfeet[0] >= 0 && sfeet[1] >= 0);
    AK_CHECK(tarm[0] >= 0 && tarm[1] >= 0 && sarm[0] >= 0 && sarm[1] >= 0);
    if (tfeet[0] < 0 || tfeet[1] < 0 || sfeet[0] < 0 || sfeet[1] < 0 || tarm[0] < 0 || tarm[1] < 0 || sarm[0] < 0 ||
        sarm[1] < 0)
        return;
    ak_retarget_stats s0, s1;
    run_result raw = run(src, dst, map, false, tfeet, sfeet, tarm, sarm, &s0);
    run_result fixed = run(src, dst, map, true, tfeet, sfeet, tarm, sarm, &s1);
    printf("  %s: lowest ankle %.4f m from its rest height (%.4f with the clean-up), upper arm within %.2f deg of the "
           "source's\n", what, raw.floor_gap, fixed.floor_gap, raw.arm_angle);
    /* the feet reach the floor and no lower: the root's height is not counted twice */
    AK_CHECK_MSG(fabs(raw.floor_gap) < 0.01 && fabs(fixed.floor_gap) < 0.02, "%s: lowest ankle %.4f / %.4f m off its rest height",
                 what, raw.floor_gap, fixed.floor_gap);
    /* the upper arm follows the source's upper arm, not its collarbone */
    AK_CHECK_MSG(raw.arm_angle < 1.0, "%s: the upper arm strays %.2f deg from the source's", what, raw.arm_angle);
    printf("  %s: %zu frames, %zu joints mapped, root scale %.4f, %zu contact frame pairs, foot slide %.4g -> %.4g "
           "(%.2f%%), %zu frames pinned (%zu out of reach), bone length error %.2g\n",
           what, s1.frame_count, s1.mapped_count, (double)s1.root_scale, fixed.contact_pairs, raw.slide, fixed.slide,
           raw.slide > 0 ? 100.0 * fixed.slide / raw.slide : 0.0, s1.pinned_frames, s1.unreached_frames, fmax(raw.bone_error, fixed.bone_error));
    AK_CHECK(raw.finite && fixed.finite);
    AK_CHECK_MSG(raw.bone_error < 1e-4 && fixed.bone_error < 1e-4, "%s: bone lengths changed by %.3g, %.3g", what,
                 raw.bone_error, fixed.bone_error);
    AK_CHECK_MSG(fixed.contact_pairs > 10, "%s: only %zu contact frame pairs", what, fixed.contact_pairs);
    AK_CHECK_MSG(raw.slide > 0 && fixed.slide <= SLIDE_RATIO_BOUND * raw.slide, "%s: slide %.4g with clean-up, %.4g without",
                 what, fixed.slide, raw.slide);
}

AK_TEST(cmu_bvh_onto_builtin_and_cesiumman) {
    char path[1200];
    if (!ak_test_asset(path, sizeof path, "bvh/02_01.bvh")) {
        AK_SKIP("bvh/02_01.bvh absent (set ANIMKIT_ASSETS)");
        return;
    }
    ak_scene *src = NULL, *human = NULL, *cesium = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(path, NULL, NULL, &src, &diag), AK_OK);
    AK_CHECK_EQ(ak_builtin_create("humanoid", NULL, NULL, &human), AK_OK);
    if (src && human) check_target("02_01.bvh -> builtin:humanoid", src, human, NULL, "left_ankle", "right_ankle", "left_shoulder",
                                    "left_elbow");
    char cpath[1200];
    if (src && ak_test_asset(cpath, sizeof cpath, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb") &&
        ak_io_load(cpath, NULL, NULL, &cesium, &diag) == AK_OK) {
        size_t nt = ak_scene_joint_count(cesium);
        int32_t* map = malloc(nt * sizeof *map);
        for (size_t k = 0; k < nt; ++k) map[k] = -1;
        for (size_t i = 0; i < sizeof k_cesium_map / sizeof k_cesium_map[0]; ++i) {
            int t = ak_skeleton_find_joint(cesium->skeleton, k_cesium_map[i][0]);
            int s = ak_skeleton_find_joint(src->skeleton, k_cesium_map[i][1]);
            AK_CHECK_MSG(t >= 0 && s >= 0, "map %s -> %s", k_cesium_map[i][0], k_cesium_map[i][1]);
            if (t >= 0) map[t] = s;
        }
        check_target("02_01.bvh -> CesiumMan", src, cesium, map, "leg_joint_L_3", "leg_joint_R_3",
                     "Skeleton_arm_joint_L__4_", "Skeleton_arm_joint_L__3_");
        free(map);
    } else {
        AK_SKIP("CesiumMan.glb absent");
    }
    ak_scene_destroy(src);
    ak_scene_destroy(human);
    ak_scene_destroy(cesium);
}


/* ---- automatic mapping ------------------------------------------------------------------------ */

/* The joint each template bone must land on, written by hand from each file's hierarchy and
 * rest pose ("" = none), in ak_humanoid_bone order from hips. */
typedef struct role_case {
    const char *file, *roles[AK_BONE_COUNT - 1];
    bool slow; /* a long file (2 MB): checked by the slow entry */
} role_case;

#define CMU_ROLES                                                                                               \
    {"Hips", "LowerBack", "Spine", "Spine1", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand", \
     "RightShoulder", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",    \
     "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}

static const role_case k_role_cases[] = {
    {"bvh/01_01.bvh", CMU_ROLES, true},
    {"bvh/02_01.bvh", CMU_ROLES, false},
    {"bvh/49_04.bvh", CMU_ROLES, false},
    {"bvh/131_03.bvh",
     {"Hips", "lowerback", "Chest", "Chest2", "lowerneck", "Head", "LeftCollar", "LeftShoulder", "LeftElbow",
      "LeftWrist", "RightCollar", "RightShoulder", "RightElbow", "RightWrist", "LeftHip", "LeftKnee", "LeftAnkle",
      "LeftToe", "RightHip", "RightKnee", "RightAnkle", "RightToe"},
     false},
    {"builtin:humanoid",
     {"pelvis", "spine_01", "spine_02", "", "neck", "head", "", "left_shoulder", "left_elbow", "left_wrist", "",
      "right_shoulder", "right_elbow", "right_wrist", "left_hip", "left_knee", "left_ankle", "", "right_hip",
      "right_knee", "right_ankle", ""},
     false},
    {"gltf/CesiumMan/glTF-Binary/CesiumMan.glb",
     {"Skeleton_torso_joint_1", "Skeleton_torso_joint_2", "torso_joint_3", "", "Skeleton_neck_joint_1",
      "Skeleton_neck_joint_2", "", "Skeleton_arm_joint_L__4_", "Skeleton_arm_joint_L__3_", "Skeleton_arm_joint_L__2_", "",
      "Skeleton_arm_joint_R", "Skeleton_arm_joint_R__2_", "Skeleton_arm_joint_R__3_", "leg_joint_L_1", "leg_joint_L_2",
      "leg_joint_L_3", "leg_joint_L_5", "leg_joint_R_1", "leg_joint_R_2", "leg_joint_R_3", "leg_joint_R_5"},
     false},
};

static ak_scene* load_case(const char* file) {
    ak_scene* s = NULL;
    ak_diag diag;
    char path[1200];
    if (strncmp(file, "builtin:", 8) == 0) ak_builtin_create(file + 8, NULL, NULL, &s);
    else if (ak_test_asset(path, sizeof path, file)) ak_io_load(path, NULL, NULL, &s, &diag);
    return s;
}

/* Every BVH of the shared assets, builtin:humanoid and CesiumMan: each template bone on the
 * joint the table above names; every one a humanoid, left/right from the toes where there
 * are toes. Fox: the template's topology fits (a quadruped has the same tree) but it does not
 * stand: not a humanoid, and the reason given. */
static void check_asset_roles(bool slow) {
    for (size_t c = 0; c < sizeof k_role_cases / sizeof k_role_cases[0]; ++c) {
        if (k_role_cases[c].slow != slow) continue;
        ak_scene* s = load_case(k_role_cases[c].file);
        if (!s) {
            AK_SKIP("asset absent (set ANIMKIT_ASSETS)");
            continue;
        }
        ak_humanoid_roles r;
        ak_diag diag;
        AK_CHECK_MSG(ak_humanoid_roles_find(s->skeleton, NULL, &r, &diag) == AK_OK, "%s: %s", k_role_cases[c].file,
                     diag.message);
        int wrong = 0;
        for (int b = 1; b < AK_BONE_COUNT; ++b) {
            const char* want = k_role_cases[c].roles[b - 1];
            const char* got = r.joint[b] >= 0 ? ak_skeleton_joint_name(s->skeleton, (size_t)r.joint[b]) : "";
            if (strcmp(want, got) != 0) ++wrong;
            AK_CHECK_MSG(strcmp(want, got) == 0, "%s: %s is '%s', expected '%s'", k_role_cases[c].file,
                         ak_humanoid_bone_name(b), got, want);
        }
        bool toes = k_role_cases[c].roles[AK_BONE_LEFT_TOES - 1][0] != '\0';
        AK_CHECK(r.is_humanoid && r.sides == (toes ? AK_SIDES_TOES : AK_SIDES_NAMES));
        printf("  %s: %d of 22 bones as expected, score %.2f, spine %.1f deg from the legs' up, sides from %s\n",
               k_role_cases[c].file, 22 - wrong, (double)r.score, (double)r.spine_angle, toes ? "toes" : "names");
        ak_scene_destroy(s);
    }
}

AK_TEST(automatic_roles_of_the_long_bvh) { check_asset_roles(true); }

AK_TEST(automatic_roles_of_the_assets) {
    check_asset_roles(false);
    ak_scene* fox = load_case("gltf/Fox/glTF-Binary/Fox.glb");
    if (!fox) {
        AK_SKIP("Fox absent");
        return;
    }
    ak_humanoid_roles r;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    AK_CHECK_EQ(ak_humanoid_roles_find(fox->skeleton, NULL, &r, &diag), AK_ERR_NOT_FOUND);
    AK_CHECK(!r.is_humanoid && r.spine_angle > 45.0f);
    AK_CHECK_MSG(strstr(diag.message, "not a humanoid") != NULL, "%s", diag.message);
    printf("  Fox: %s\n", diag.message);
    ak_scene_destroy(fox);
}

/* Model-space direction of the bone from joint a to joint b at time t of clip (rest pose for
 * joints the clip leaves out). */
static ak_vec3 bone_dir(const ak_skeleton* sk, const ak_clip* clip, float t, int a, int b, ak_transform* local,
                        ak_mat4* model) {
    size_t n = ak_skeleton_joint_count(sk);
    memcpy(local, ak_skeleton_rest_pose(sk).ptr, n * sizeof *local);
    ak_clip_sample(clip, t, NULL, (ak_transform_span){local, n}, (ak_f32_span){0}, (ak_f32_span){0});
    ak_skeleton_local_to_model(sk, (ak_transform_cspan){local, n}, (ak_mat4_span){model, n});
    return ak_vec3_sub(joint_pos(&model[b]), joint_pos(&model[a]));
}

/* 02_01.bvh onto CesiumMan with the automatic map and with the hand-written map the tests used
 * before (k_cesium_map), and onto builtin:humanoid automatically and by name: over the whole
 * clip (at 10 fps), the model-space direction of every arm and leg bone (upper arm, forearm, thigh, shin,
 * both sides) agrees within 2 degrees. */
AK_TEST(automatic_map_matches_the_hand_written_one) {
    ak_scene* src = load_case("bvh/02_01.bvh");
    ak_scene* cesium = load_case("gltf/CesiumMan/glTF-Binary/CesiumMan.glb");
    ak_scene* human = load_case("builtin:humanoid");
    if (!src || !cesium || !human) {
        AK_SKIP("assets absent (set ANIMKIT_ASSETS)");
        ak_scene_destroy(src), ak_scene_destroy(cesium), ak_scene_destroy(human);
        return;
    }
    ak_humanoid_roles sr;
    AK_CHECK_EQ(ak_humanoid_roles_find(src->skeleton, NULL, &sr, NULL), AK_OK);
    for (int c = 0; c < 2; ++c) {
        const ak_scene* dst = c == 0 ? cesium : human;
        const ak_skeleton* ts = dst->skeleton;
        size_t nt = ak_skeleton_joint_count(ts);
        int32_t* hand = malloc(nt * sizeof *hand);
        int32_t* autom = malloc(nt * sizeof *autom);
        if (c == 0) {
            for (size_t k = 0; k < nt; ++k) hand[k] = -1;
            for (size_t i = 0; i < sizeof k_cesium_map / sizeof k_cesium_map[0]; ++i)
                hand[ak_skeleton_find_joint(ts, k_cesium_map[i][0])] = ak_skeleton_find_joint(src->skeleton, k_cesium_map[i][1]);
            /* the shipped copy of that map reads as the same map */
            FILE* f = fopen(AK_SOURCE_DIR "/examples/retarget_cesiumman.map", "rb");
            char text[4096];
            size_t n = f ? fread(text, 1, sizeof text, f) : 0;
            if (f) fclose(f);
            AK_CHECK_MSG(n > 0 && n < sizeof text, "examples/retarget_cesiumman.map: unreadable");
            AK_CHECK_EQ(ak_retarget_map_parse(text, n, src->skeleton, ts, (ak_i32_span){autom, nt}, NULL, NULL), AK_OK);
            AK_CHECK(memcmp(autom, hand, nt * sizeof *hand) == 0);
        } else {
            ak_retarget_map_by_name(src->skeleton, ts, (ak_i32_span){hand, nt}, NULL);
        }
        ak_humanoid_roles tr;
        AK_CHECK_EQ(ak_humanoid_roles_find(ts, NULL, &tr, NULL), AK_OK);
        size_t mapped = 0;
        AK_CHECK_EQ(ak_retarget_map_by_roles(src->skeleton, &sr, ts, &tr, (ak_i32_span){autom, nt}, &mapped), AK_OK);
        ak_clip *a = NULL, *b = NULL;
        ak_retarget_desc d = {.source = src->skeleton, .clip = src->clips[0], .target = ts, .source_of_target = {hand, nt},
                              .frame_rate = 10};
        AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &a, NULL, NULL), AK_OK);
        d.source_of_target.ptr = autom;
        AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &b, NULL, NULL), AK_OK);
        static const int bones[8][2] = {
            {AK_BONE_LEFT_UPPER_ARM, AK_BONE_LEFT_LOWER_ARM},   {AK_BONE_LEFT_LOWER_ARM, AK_BONE_LEFT_HAND},
            {AK_BONE_RIGHT_UPPER_ARM, AK_BONE_RIGHT_LOWER_ARM}, {AK_BONE_RIGHT_LOWER_ARM, AK_BONE_RIGHT_HAND},
            {AK_BONE_LEFT_UPPER_LEG, AK_BONE_LEFT_LOWER_LEG},   {AK_BONE_LEFT_LOWER_LEG, AK_BONE_LEFT_FOOT},
            {AK_BONE_RIGHT_UPPER_LEG, AK_BONE_RIGHT_LOWER_LEG}, {AK_BONE_RIGHT_LOWER_LEG, AK_BONE_RIGHT_FOOT}};
        ak_transform* local = malloc(nt * sizeof *local);
        ak_mat4* model = malloc(nt * sizeof *model);
        double worst = 0.0;
        size_t frames = 0;
        for (float t = 0.0f; a && b && t <= ak_clip_duration(a); t += 1.0f / 10.0f, ++frames)
            for (int i = 0; i < 8; ++i) {
                int j0 = tr.joint[bones[i][0]], j1 = tr.joint[bones[i][1]];
                ak_vec3 u = bone_dir(ts, a, t, j0, j1, local, model), v = bone_dir(ts, b, t, j0, j1, local, model);
                double cs = ak_vec3_dot(u, v) / ((double)ak_vec3_length(u) * (double)ak_vec3_length(v));
                worst = fmax(worst, acos(fmax(-1.0, fmin(1.0, cs))) * (180.0 / 3.14159265358979323846));
            }
        printf("  02_01.bvh -> %s: automatic map (%zu joints) vs %s: arm and leg bones within %.4f deg over %zu frames\n",
               c == 0 ? "CesiumMan" : "builtin:humanoid", mapped, c == 0 ? "the hand-written map" : "the name map", worst,
               frames);
        AK_CHECK(frames > 25);
        AK_CHECK_MSG(worst < 2.0, "bones differ by %.3f deg", worst);
        /* the automatic map holds every pair of the hand-written one but the torso's */
        for (size_t k = 0; k < nt; ++k) {
            bool torso = (int32_t)k == tr.joint[AK_BONE_SPINE] || (int32_t)k == tr.joint[AK_BONE_CHEST];
            if (hand[k] >= 0 && !torso)
                AK_CHECK_MSG(autom[k] == hand[k], "%s: %s -> %s, the hand map says %s", c == 0 ? "CesiumMan" : "humanoid",
                             ak_skeleton_joint_name(ts, k), autom[k] >= 0 ? ak_skeleton_joint_name(src->skeleton, (size_t)autom[k]) : "-",
                             ak_skeleton_joint_name(src->skeleton, (size_t)hand[k]));
        }
        /* the written map reads back as the same map */
        size_t need = 0;
        ak_retarget_map_write(src->skeleton, &sr, ts, &tr, (ak_i32_cspan){autom, nt}, NULL, 0, &need);
        char* text = malloc(need + 1);
        AK_CHECK_EQ(ak_retarget_map_write(src->skeleton, &sr, ts, &tr, (ak_i32_cspan){autom, nt}, text, need + 1, NULL), AK_OK);
        AK_CHECK_EQ(ak_retarget_map_parse(text, need, src->skeleton, ts, (ak_i32_span){hand, nt}, NULL, NULL), AK_OK);
        AK_CHECK(memcmp(hand, autom, nt * sizeof *hand) == 0);
        free(text), free(local), free(model), free(hand), free(autom);
        ak_clip_destroy(a), ak_clip_destroy(b);
    }
    ak_scene_destroy(src), ak_scene_destroy(cesium), ak_scene_destroy(human);
}

#ifdef AK_CLI_PATH
/* Lines the last run_cli printed on stderr, the last of them, and all of it (truncated). */
static int g_cli_lines;
static char g_cli_last[1024];
static char g_cli_err[16384];

/* Run the CLI; returns the exit status and the first line of stderr in line. */
static int run_cli(const char* args, char* line, size_t n) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "'%s' retarget %s 2>&1 >/dev/null", AK_CLI_PATH, args);
    FILE* p = popen(cmd, "r");
    if (!p) return -1;
    line[0] = '\0';
    char buf[1024];
    int lines = 0;
    size_t at = 0;
    g_cli_last[0] = g_cli_err[0] = '\0';
    while (fgets(buf, sizeof buf, p)) {
        if (lines++ == 0) snprintf(line, n, "%s", buf);
        snprintf(g_cli_last, sizeof g_cli_last, "%s", buf);
        if (at < sizeof g_cli_err) at += (size_t)snprintf(g_cli_err + at, sizeof g_cli_err - at, "%s", buf);
    }
    g_cli_lines = lines;
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* The exported file stands on the floor: `animkit retarget` of a CMU walk onto builtin:humanoid
 * and onto CesiumMan, the .glb loaded back and sampled at 30 fps; the lowest ankle over the
 * clip is within 1 cm of the lowest ankle at rest, and the hips stay between 0.8 and 1.1 of
 * their rest height above it (the hip height used to be counted twice: 1.86 m for 0.95). */
AK_TEST(cli_exports_stand_on_the_floor) {
    char bvh[1200], cesium[1200];
    if (!ak_test_asset(bvh, sizeof bvh, "bvh/02_01.bvh") ||
        !ak_test_asset(cesium, sizeof cesium, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb")) {
        AK_SKIP("assets absent (set ANIMKIT_ASSETS)");
        return;
    }
    static const struct {
        const char *target, *out, *ankles[2], *hips;
        bool needs_map;
    } cases[] = {{"builtin:humanoid", "floor_human.glb", {"left_ankle", "right_ankle"}, "pelvis", false},
                 {NULL, "floor_cesium.glb", {"leg_joint_L_3", "leg_joint_R_3"}, "Skeleton_torso_joint_1", true}};
    for (int c = 0; c < 2; ++c) {
        char args[4096], line[1024];
        if (cases[c].needs_map) {
            FILE* m = fopen("floor_cesium.map", "w");
            AK_CHECK(m != NULL);
            if (!m) return;
            for (size_t i = 0; i < sizeof k_cesium_map / sizeof k_cesium_map[0]; ++i)
                fprintf(m, "%s = %s\n", k_cesium_map[i][0], k_cesium_map[i][1]);
            fclose(m);
            snprintf(args, sizeof args, "'%s' '%s' --map floor_cesium.map -o %s", bvh, cesium, cases[c].out);
        } else {
            snprintf(args, sizeof args, "'%s' %s -o %s", bvh, cases[c].target, cases[c].out);
        }
        AK_CHECK_MSG(run_cli(args, line, sizeof line) == 0, "%s", line);
        ak_scene* s = NULL;
        ak_diag diag;
        AK_CHECK_MSG(ak_io_load(cases[c].out, NULL, NULL, &s, &diag) == AK_OK, "%s", diag.message);
        if (!s) continue;
        const ak_skeleton* sk = s->skeleton;
        size_t n = ak_skeleton_joint_count(sk);
        int a0 = ak_skeleton_find_joint(sk, cases[c].ankles[0]), a1 = ak_skeleton_find_joint(sk, cases[c].ankles[1]);
        int hip = ak_skeleton_find_joint(sk, cases[c].hips);
        AK_CHECK(a0 >= 0 && a1 >= 0 && hip >= 0 && s->clip_count >= 1);
        if (a0 < 0 || a1 < 0 || hip < 0 || s->clip_count < 1) {
            ak_scene_destroy(s);
            continue;
        }
        ak_transform* local = malloc(n * sizeof *local);
        ak_mat4* model = malloc(n * sizeof *model);
        ak_skeleton_local_to_model(sk, ak_skeleton_rest_pose(sk), (ak_mat4_span){model, n});
        double rest_floor = fmin(joint_pos(&model[a0]).y, joint_pos(&model[a1]).y);
        double rest_hip = joint_pos(&model[hip]).y - rest_floor;
        double low = 1e30, hip_lo = 1e30, hip_hi = -1e30;
        const ak_clip* clip = s->clips[s->clip_count - 1];
        for (double t = 0.0; t <= (double)ak_clip_duration(clip); t += 1.0 / 30.0) {
            memcpy(local, ak_skeleton_rest_pose(sk).ptr, n * sizeof *local);
            ak_clip_sample(clip, (float)t, NULL, (ak_transform_span){local, n}, (ak_f32_span){0}, (ak_f32_span){0});
            ak_skeleton_local_to_model(sk, (ak_transform_cspan){local, n}, (ak_mat4_span){model, n});
            low = fmin(low, fmin(joint_pos(&model[a0]).y, joint_pos(&model[a1]).y));
            double h = joint_pos(&model[hip]).y - rest_floor;
            hip_lo = fmin(hip_lo, h), hip_hi = fmax(hip_hi, h);
        }
        printf("  %s: lowest ankle %+.4f m from rest, hips %.3f..%.3f m above the floor (rest %.3f)\n", cases[c].out,
               low - rest_floor, hip_lo, hip_hi, rest_hip);
        AK_CHECK_MSG(fabs(low - rest_floor) < 0.01, "%s: lowest ankle %.4f m from its rest height", cases[c].out,
                     low - rest_floor);
        AK_CHECK_MSG(hip_lo > 0.8 * rest_hip && hip_hi < 1.1 * rest_hip, "%s: hips at %.3f..%.3f m, rest %.3f", cases[c].out,
                     hip_lo, hip_hi, rest_hip);
        free(local), free(model);
        ak_scene_destroy(s);
    }
}

/* The retarget GIF frames each figure (a walk travels several body lengths: framing the whole
 * path left the figures a quarter of the panel high), the mesh drawn without the skeleton over
 * it: in the middle frame, each half of the image has coloured figure pixels (the skeleton's
 * joints on the BVH side, the clay mesh on the other: red above blue by more than 12, where
 * the grid, the floor and the background are grey) spanning at least 40% of its height, their
 * box centred in the middle third of the half (the whole-path framing put them at the edges). */
AK_TEST(cli_gif_frames_each_figure) {
    char bvh[1200];
    if (!ak_test_asset(bvh, sizeof bvh, "bvh/02_01.bvh")) {
        AK_SKIP("bvh/02_01.bvh absent (set ANIMKIT_ASSETS)");
        return;
    }
    char args[2048], line[1024];
    snprintf(args, sizeof args, "'%s' builtin:humanoid --size 200x150 --fps 4 -o framing.gif", bvh);
    AK_CHECK_MSG(run_cli(args, line, sizeof line) == 0, "%s", line);
    int w = 0, h = 0, frames = 0;
    AK_CHECK_EQ(ak_gif_info("framing.gif", &w, &h, &frames), AK_OK);
    if (w <= 0 || h <= 0 || frames <= 0) return;
    ak_image img = {.pixels = malloc((size_t)w * (size_t)h * 4), .width = w, .height = h};
    AK_CHECK_EQ(ak_gif_read_frame("framing.gif", frames / 2, &img), AK_OK);
    for (int half = 0; half < 2; ++half) {
        int top = h, bottom = -1, left = w, right = -1;
        const int x0 = half * w / 2, x1 = (half + 1) * w / 2;
        for (int y = 0; y < h; ++y)
            for (int x = x0; x < x1; ++x) {
                const uint8_t* px = img.pixels + ((size_t)y * (size_t)w + (size_t)x) * 4;
                if ((int)px[0] - (int)px[2] > 12 && px[0] >= px[1]) {
                    if (y < top) top = y;
                    if (y > bottom) bottom = y;
                    if (x < left) left = x;
                    if (x > right) right = x;
                }
            }
        double span = bottom >= top ? (double)(bottom - top + 1) / (double)h : 0.0;
        double centre = right >= left ? (0.5 * (left + right) - x0) / (double)(x1 - x0) : -1.0;
        printf("  framing.gif %s: the figure spans %.0f%% of the height, centred at %.0f%% of the panel's width\n",
               half ? "target" : "source", 100.0 * span, 100.0 * centre);
        AK_CHECK_MSG(span >= 0.40 && centre > 1.0 / 3.0 && centre < 2.0 / 3.0,
                     "%s panel: the figure spans %.0f%% of the height, centred at %.0f%% of the width",
                     half ? "target" : "source", 100.0 * span, 100.0 * centre);
    }
    free(img.pixels);
}

/* Without --map: the automatic map's table on stderr (or --report FILE), --map-out FILE
 * writes it as a map file that --map reads back; Fox (a quadruped) is refused with exit 1, the
 * table of what matched and a last line naming the file, "not a humanoid" and --map. */
AK_TEST(cli_automatic_map) {
    char bvh[1200], cesium[1200], fox[1200];
    if (!ak_test_asset(bvh, sizeof bvh, "bvh/02_01.bvh") ||
        !ak_test_asset(cesium, sizeof cesium, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb") ||
        !ak_test_asset(fox, sizeof fox, "gltf/Fox/glTF-Binary/Fox.glb")) {
        AK_SKIP("assets absent (set ANIMKIT_ASSETS)");
        return;
    }
    char args[4096], line[1024];
    snprintf(args, sizeof args, "'%s' '%s' --fps 5 -o auto_cesium.glb", bvh, cesium);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 0);
    AK_CHECK_MSG(strstr(g_cli_err, "leg_joint_L_1") && strstr(g_cli_err, "= LeftUpLeg") &&
                 strstr(g_cli_err, "leftUpperLeg"), "%s", g_cli_err);
    snprintf(args, sizeof args, "'%s' '%s' --fps 5 --map-out auto.map --report auto.txt -o auto_cesium.glb", bvh, cesium);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 0);
    AK_CHECK_MSG(!strstr(g_cli_err, "= LeftUpLeg"), "the table went to stderr despite --report: %s", g_cli_err);
    FILE* f = fopen("auto.map", "r");
    char text[8192] = "";
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f) fclose(f);
    text[n] = '\0';
    AK_CHECK_MSG(strstr(text, "Skeleton_arm_joint_L__4_") && strstr(text, "= LeftArm"), "%s", text);
    snprintf(args, sizeof args, "'%s' '%s' --fps 5 --map auto.map -o auto_cesium.glb", bvh, cesium);
    AK_CHECK_MSG(run_cli(args, line, sizeof line) == 0, "%s", line);
    AK_CHECK_MSG(strstr(g_cli_err, "19 of 22 target joints driven") != NULL, "%s", g_cli_err);
    /* Fox */
    snprintf(args, sizeof args, "'%s' '%s' -o auto_fox.glb", bvh, fox);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 1);
    AK_CHECK_MSG(strstr(g_cli_last, "Fox.glb") && strstr(g_cli_last, "not a humanoid") && strstr(g_cli_last, "--map"),
                 "%s", g_cli_last);
    AK_CHECK_MSG(strstr(g_cli_err, "NOT a humanoid") && strstr(g_cli_err, "b_Hip_01"), "%s", g_cli_err);
    struct stat st;
    AK_CHECK(stat("auto_fox.glb", &st) != 0);
}

AK_TEST(cli_retarget) {
    char bvh[1200], cesium[1200], nomotion[1200];
    if (!ak_test_asset(bvh, sizeof bvh, "bvh/02_01.bvh") ||
        !ak_test_asset(cesium, sizeof cesium, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb") ||
        !ak_test_asset(nomotion, sizeof nomotion, "gltf/MorphPrimitivesTest/glTF-Binary/MorphPrimitivesTest.glb")) {
        AK_SKIP("assets absent (set ANIMKIT_ASSETS)");
        return;
    }
    char dir[] = "/tmp/test_retarget_cli.XXXXXX";
    if (!mkdtemp(dir)) {
        AK_FAIL_("mkdtemp");
        return;
    }
    char args[4096], line[1024], out[256], mapf[256];
    /* builtin humanoid by names, glb out: loads back with the clip on 17 joints */
    snprintf(out, sizeof out, "%s/human.glb", dir);
    snprintf(args, sizeof args, "'%s' builtin:humanoid -o '%s'", bvh, out);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 0);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(out, NULL, NULL, &s, &diag), AK_OK);
    if (s) {
        AK_CHECK_EQ(s->clip_count, 1u);
        AK_CHECK_EQ(ak_scene_joint_count(s) >= 17u, true);
    }
    ak_scene_destroy(s);
    /* CesiumMan with a map file */
    snprintf(mapf, sizeof mapf, "%s/cesium.map", dir);
    FILE* f = fopen(mapf, "w");
    fprintf(f, "# CesiumMan <- CMU\n");
    for (size_t i = 0; i < sizeof k_cesium_map / sizeof k_cesium_map[0]; ++i)
        fprintf(f, "%s = %s\n", k_cesium_map[i][0], k_cesium_map[i][1]);
    fclose(f);
    snprintf(out, sizeof out, "%s/cesium.gltf", dir);
    snprintf(args, sizeof args, "'%s' '%s' --map '%s' -o '%s'", bvh, cesium, mapf, out);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 0);
    s = NULL;
    AK_CHECK_EQ(ak_io_load(out, NULL, NULL, &s, &diag), AK_OK);
    ak_scene_destroy(s);
    /* no name in common: the automatic map */
    snprintf(args, sizeof args, "'%s' '%s' -o '%s'", bvh, cesium, out);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 0);
    /* bad map files: each exits 1 with one line naming the file and the problem */
    struct {
        const char* text;
        const char* expect;
    } bad[] = {
        {"leg_joint_L_1 = LeftUpLeg\nnot_a_joint = Hips\n", "has no joint 'not_a_joint'"},
        {"leg_joint_L_1 = NoSuchSourceJoint\n", "has no joint 'NoSuchSourceJoint'"},
        {"leg_joint_L_1 LeftUpLeg\n", "expected 'TARGET_JOINT = SOURCE_JOINT'"},
        {"# nothing\n", "maps no joint"},
        {"leg_joint_L_1 = LeftUpLeg\nleg_joint_L_1 = RightUpLeg\n", "mapped twice"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        f = fopen(mapf, "w");
        fputs(bad[i].text, f);
        fclose(f);
        snprintf(args, sizeof args, "'%s' '%s' --map '%s' -o '%s'", bvh, cesium, mapf, out);
        AK_CHECK_EQ(run_cli(args, line, sizeof line), 1);
        AK_CHECK_MSG(strstr(line, mapf) && strstr(line, bad[i].expect), "map %zu: %s", i, line);
        AK_CHECK_MSG(g_cli_lines == 1, "map %zu: %d lines on stderr, one expected", i, g_cli_lines);
    }
    snprintf(args, sizeof args, "'%s' '%s' --map '%s/missing.map' -o '%s'", bvh, cesium, dir, out);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 1);
    AK_CHECK(strstr(line, "missing.map") != NULL);
    AK_CHECK_EQ(g_cli_lines, 1);
    /* a source without a clip */
    snprintf(args, sizeof args, "'%s' builtin:humanoid -o '%s'", nomotion, out);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 1);
    AK_CHECK_EQ(g_cli_lines, 1);
    AK_CHECK(strstr(line, "MorphPrimitivesTest.glb") && strstr(line, "no clip"));
    /* usage */
    snprintf(args, sizeof args, "'%s' builtin:humanoid -o '%s/x.obj'", bvh, dir);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 2);
    /* GIF */
    snprintf(out, sizeof out, "%s/side.gif", dir);
    snprintf(args, sizeof args, "'%s' builtin:humanoid --size 64x64 --fps 10 -o '%s'", bvh, out);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 0);
    struct stat st;
    AK_CHECK(stat(out, &st) == 0 && st.st_size > 1000);
    snprintf(args, sizeof args, "rm -rf '%s'", dir);
    AK_CHECK_EQ(system(args), 0);
}
#endif

int main(void) {
    AK_RUN(cmu_bvh_onto_builtin_and_cesiumman);
    AK_RUN(automatic_roles_of_the_assets);
    AK_RUN(automatic_map_matches_the_hand_written_one);
    AK_RUN_SLOW(automatic_roles_of_the_long_bvh);
#ifdef AK_CLI_PATH
    AK_RUN(cli_exports_stand_on_the_floor);
    AK_RUN_SLOW(cli_gif_frames_each_figure); /* a whole retarget GIF: end to end */
    AK_RUN(cli_automatic_map);
    AK_RUN_SLOW(cli_retarget);
#endif
    return ak_test_finish();
}
