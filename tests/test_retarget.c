/* Retargeting on hand-made skeletons: identity onto the same skeleton, a uniformly scaled copy
 * (positions scale, rotations identical), a copy whose rest arms are turned 45 degrees (model
 * bone directions equal), name recognition of common rigs, and the desc rules. */
#include <animkit/retarget.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ak_test.h"

enum { NJ = 15, NF = 31 };

static const char* const k_names[NJ] = {"pelvis",   "spine_01",  "neck",       "head",       "left_shoulder",
                                        "left_elbow", "left_wrist", "right_shoulder", "right_elbow", "right_wrist",
                                        "left_hip", "left_knee", "left_ankle", "right_hip",  "right_knee"};
static const int k_parents[NJ] = {-1, 0, 1, 2, 1, 4, 5, 1, 7, 8, 0, 10, 11, 0, 13};
static const float k_offsets[NJ][3] = {{0, 1, 0},     {0, 0.3f, 0},  {0, 0.3f, 0},  {0, 0.15f, 0}, {0.2f, 0.25f, 0},
                                       {0.3f, 0, 0},  {0.25f, 0, 0}, {-0.2f, 0.25f, 0}, {-0.3f, 0, 0}, {-0.25f, 0, 0},
                                       {0.1f, 0, 0},  {0, -0.45f, 0}, {0, -0.45f, 0}, {-0.1f, 0, 0}, {0, -0.45f, 0}};

/* scale: rest offsets multiplied; arm_turn: extra rest rotation of the shoulders (radians). */
static ak_skeleton* make_skeleton(float scale, float arm_turn) {
    ak_joint_desc j[NJ];
    for (int i = 0; i < NJ; ++i) {
        ak_quat q = ak_quat_identity();
        if (i == 4) q = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), -arm_turn);
        if (i == 7) q = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), arm_turn);
        j[i] = (ak_joint_desc){.name = k_names[i], .parent = k_parents[i],
                               .rest = ak_transform_make(ak_vec3_scale(ak_vec3_make(k_offsets[i][0], k_offsets[i][1], k_offsets[i][2]), scale),
                                                         q, ak_vec3_make(1, 1, 1))};
    }
    ak_skeleton* s = NULL;
    ak_skeleton_create(&(ak_skeleton_desc){.joints = j, .joint_count = NJ}, NULL, &s, NULL);
    return s;
}

/* A 1-second clip: every joint swings about a different axis, the pelvis walks along +Z. */
static ak_clip* make_clip(const ak_skeleton* sk) {
    static ak_transform poses[NF * NJ];
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    for (int f = 0; f < NF; ++f) {
        float t = (float)f / 30.0f;
        for (int j = 0; j < NJ; ++j) {
            ak_vec3 axis = ak_vec3_normalize(ak_vec3_make((float)(j % 3) + 0.5f, (float)((j + 1) % 2), (float)(j % 5) - 2.0f));
            ak_quat q = ak_quat_from_axis_angle(axis, 0.6f * sinf(6.28f * t + 0.4f * (float)j));
            poses[f * NJ + j] = rest.ptr[j];
            poses[f * NJ + j].rotation = ak_quat_mul(rest.ptr[j].rotation, q);
        }
        poses[f * NJ].translation = ak_vec3_make(0.1f * sinf(3.0f * t), 1.0f + 0.05f * cosf(12.0f * t), 1.2f * t);
    }
    ak_clip* c = NULL;
    ak_clip_bake(&(ak_clip_bake_desc){.poses = poses, .frame_count = NF, .joint_count = NJ, .frame_rate = 30}, NULL, &c, NULL);
    return c;
}

static void model_at(const ak_skeleton* sk, const ak_clip* c, float t, ak_transform* local, ak_mat4* model) {
    memcpy(local, ak_skeleton_rest_pose(sk).ptr, NJ * sizeof *local);
    ak_clip_sample(c, t, NULL, (ak_transform_span){local, NJ}, (ak_f32_span){0}, (ak_f32_span){0});
    ak_skeleton_local_to_model(sk, (ak_transform_cspan){local, NJ}, (ak_mat4_span){model, NJ});
}

/* Angle of the rotation between a and b, in double (atan2 stays accurate near zero, where
 * acos of the dot product loses half the digits). */
static double quat_angle(ak_quat a, ak_quat b) {
    double ax = -a.x, ay = -a.y, az = -a.z, aw = a.w; /* conj(a) * b */
    double x = aw * b.x + ax * b.w + ay * b.z - az * b.y;
    double y = aw * b.y - ax * b.z + ay * b.w + az * b.x;
    double z = aw * b.z + ax * b.y - ay * b.x + az * b.w;
    double w = aw * b.w - ax * b.x - ay * b.y - az * b.z;
    return 2.0 * atan2(sqrt(x * x + y * y + z * z), fabs(w));
}

AK_TEST(identity_on_same_skeleton) {
    ak_skeleton* sk = make_skeleton(1.0f, 0.0f);
    ak_clip* src = make_clip(sk);
    ak_retarget_desc d = {.source = sk, .clip = src, .target = sk, .skip_foot_contacts = true};
    ak_clip* out = NULL;
    ak_retarget_stats st;
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &out, &st, NULL), AK_OK);
    AK_CHECK_EQ(st.mapped_count, (size_t)NJ);
    AK_CHECK_EQ(st.frame_count, (size_t)NF);
    AK_CHECK_NEAR(st.root_scale, 1.0, 1e-6);
    double worst_r = 0, worst_t = 0;
    for (int f = 0; f < NF && out; ++f) {
        float t = (float)f / 30.0f;
        ak_transform la[NJ], lb[NJ];
        ak_mat4 ma[NJ], mb[NJ];
        model_at(sk, src, t, la, ma);
        model_at(sk, out, t, lb, mb);
        for (int j = 0; j < NJ; ++j) {
            worst_r = fmax(worst_r, quat_angle(la[j].rotation, lb[j].rotation));
            worst_t = fmax(worst_t, ak_vec3_length(ak_vec3_sub(la[j].translation, lb[j].translation)));
        }
    }
    AK_CHECK_MSG(worst_r < 1e-5 && worst_t < 1e-5, "rotation %.3g rad, translation %.3g", worst_r, worst_t);
    ak_clip_destroy(out);
    ak_clip_destroy(src);
    ak_skeleton_destroy(sk);
}

AK_TEST(uniformly_scaled_copy) {
    ak_skeleton* sk = make_skeleton(1.0f, 0.0f);
    ak_skeleton* big = make_skeleton(2.5f, 0.0f);
    ak_clip* src = make_clip(sk);
    ak_retarget_desc d = {.source = sk, .clip = src, .target = big, .skip_foot_contacts = true};
    ak_clip* out = NULL;
    ak_retarget_stats st;
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &out, &st, NULL), AK_OK);
    AK_CHECK_NEAR(st.root_scale, 2.5, 1e-5);
    double worst_r = 0, worst_p = 0;
    for (int f = 0; f < NF && out; ++f) {
        float t = (float)f / 30.0f;
        ak_transform la[NJ], lb[NJ];
        ak_mat4 ma[NJ], mb[NJ];
        model_at(sk, src, t, la, ma);
        model_at(big, out, t, lb, mb);
        for (int j = 0; j < NJ; ++j) {
            worst_r = fmax(worst_r, quat_angle(la[j].rotation, lb[j].rotation));
            ak_vec3 pa = ak_vec3_scale(ak_mat4_get_translation(ma[j]), 2.5f), pb = ak_mat4_get_translation(mb[j]);
            worst_p = fmax(worst_p, ak_vec3_length(ak_vec3_sub(pa, pb)) / 2.5);
        }
    }
    AK_CHECK_MSG(worst_r < 1e-5 && worst_p < 1e-5, "rotation %.3g rad, position %.3g (relative)", worst_r, worst_p);
    /* unscaled root motion: the pelvis moves by the source's displacement as is */
    d.unscaled_root_motion = true;
    ak_clip* un = NULL;
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &un, &st, NULL), AK_OK);
    AK_CHECK_NEAR(st.root_scale, 1.0, 0);
    if (un) {
        ak_transform la[NJ], lb[NJ];
        ak_mat4 ma[NJ], mb[NJ];
        model_at(sk, src, 1.0f, la, ma);
        model_at(big, un, 1.0f, lb, mb);
        /* source pelvis went from (0,1,0) to la[0].translation; target from (0,2.5,0) */
        AK_CHECK_NEAR(lb[0].translation.z, la[0].translation.z, 1e-5);
        AK_CHECK_NEAR(lb[0].translation.y - 2.5f, la[0].translation.y - 1.0f, 1e-5);
    }
    ak_clip_destroy(un);
    ak_clip_destroy(out);
    ak_clip_destroy(src);
    ak_skeleton_destroy(sk);
    ak_skeleton_destroy(big);
}

AK_TEST(rest_pose_arms_turned_45_degrees) {
    ak_skeleton* sk = make_skeleton(1.0f, 0.0f);
    ak_skeleton* apose = make_skeleton(1.0f, 0.7853982f);
    ak_clip* src = make_clip(sk);
    ak_retarget_desc d = {.source = sk, .clip = src, .target = apose, .skip_foot_contacts = true};
    ak_clip* out = NULL;
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &out, NULL, NULL), AK_OK);
    /* the rest poses really differ: the left elbow sits elsewhere */
    ak_mat4 ra[NJ], rb[NJ];
    ak_skeleton_local_to_model(sk, ak_skeleton_rest_pose(sk), (ak_mat4_span){ra, NJ});
    ak_skeleton_local_to_model(apose, ak_skeleton_rest_pose(apose), (ak_mat4_span){rb, NJ});
    AK_CHECK(ak_vec3_length(ak_vec3_sub(ak_mat4_get_translation(ra[5]), ak_mat4_get_translation(rb[5]))) > 0.1f);
    double worst = 0;
    for (int f = 0; f < NF && out; ++f) {
        float t = (float)f / 30.0f;
        ak_transform la[NJ], lb[NJ];
        ak_mat4 ma[NJ], mb[NJ];
        model_at(sk, src, t, la, ma);
        model_at(apose, out, t, lb, mb);
        for (int c = 1; c < NJ; ++c) { /* every bone: parent joint -> joint */
            int p = k_parents[c];
            ak_vec3 da = ak_vec3_sub(ak_mat4_get_translation(ma[c]), ak_mat4_get_translation(ma[p]));
            ak_vec3 db = ak_vec3_sub(ak_mat4_get_translation(mb[c]), ak_mat4_get_translation(mb[p]));
            double cosv = ak_vec3_dot(ak_vec3_normalize(da), ak_vec3_normalize(db));
            double ang = atan2(ak_vec3_length(ak_vec3_cross(ak_vec3_normalize(da), ak_vec3_normalize(db))), cosv);
            worst = fmax(worst, ang);
        }
    }
    AK_CHECK_MSG(worst < 1e-4, "largest bone direction difference %.3g rad", worst);
    ak_clip_destroy(out);
    ak_clip_destroy(src);
    ak_skeleton_destroy(sk);
    ak_skeleton_destroy(apose);
}

AK_TEST(bone_names) {
    struct {
        const char* name;
        ak_humanoid_bone bone;
    } cases[] = {
        {"Hips", AK_BONE_HIPS},                    {"mixamorig:Hips", AK_BONE_HIPS},
        {"pelvis", AK_BONE_HIPS},                  {"mixamorig:LeftArm", AK_BONE_LEFT_UPPER_ARM},
        {"LeftForeArm", AK_BONE_LEFT_LOWER_ARM},   {"RightUpLeg", AK_BONE_RIGHT_UPPER_LEG},
        {"RightLeg", AK_BONE_RIGHT_LOWER_LEG},     {"LeftFoot", AK_BONE_LEFT_FOOT},
        {"LeftToeBase", AK_BONE_LEFT_TOES},        {"upperarm_l", AK_BONE_LEFT_UPPER_ARM},
        {"lowerarm_r", AK_BONE_RIGHT_LOWER_ARM},   {"thigh_l", AK_BONE_LEFT_UPPER_LEG},
        {"calf_r", AK_BONE_RIGHT_LOWER_LEG},       {"foot_l", AK_BONE_LEFT_FOOT},
        {"ball_r", AK_BONE_RIGHT_TOES},            {"clavicle_l", AK_BONE_LEFT_SHOULDER},
        {"leftUpperArm", AK_BONE_LEFT_UPPER_ARM},  {"rightLowerLeg", AK_BONE_RIGHT_LOWER_LEG},
        {"leftToes", AK_BONE_LEFT_TOES},           {"left_knee", AK_BONE_LEFT_LOWER_LEG},
        {"right_ankle", AK_BONE_RIGHT_FOOT},       {"left_hip", AK_BONE_LEFT_UPPER_LEG},
        {"left_wrist", AK_BONE_LEFT_HAND},         {"Head", AK_BONE_HEAD},
        {"neck_01", AK_BONE_NECK},                 {"LHipJoint", AK_BONE_NONE},
        {"LThumb", AK_BONE_NONE},                  {"b_Tail01_012", AK_BONE_NONE},
        {"UpperArm.L", AK_BONE_LEFT_UPPER_ARM},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        AK_CHECK_MSG(ak_humanoid_bone_of_name(cases[i].name) == cases[i].bone, "%s -> %s, expected %s", cases[i].name,
                     ak_humanoid_bone_name(ak_humanoid_bone_of_name(cases[i].name)), ak_humanoid_bone_name(cases[i].bone));
    AK_CHECK_STREQ(ak_humanoid_bone_name(AK_BONE_LEFT_UPPER_ARM), "leftUpperArm");
    AK_CHECK_STREQ(ak_humanoid_bone_name(AK_BONE_COUNT), "none");
    /* hierarchy: the builtin-style "left_shoulder" above "left_elbow" is the upper arm */
    ak_skeleton* sk = make_skeleton(1.0f, 0.0f);
    int32_t b[NJ];
    AK_CHECK_EQ(ak_humanoid_bones_of_skeleton(sk, (ak_i32_span)AK_SPAN(b)), AK_OK);
    AK_CHECK_EQ(b[4], AK_BONE_LEFT_UPPER_ARM);
    AK_CHECK_EQ(b[1], AK_BONE_SPINE);
    AK_CHECK_EQ(ak_humanoid_bones_of_skeleton(sk, (ak_i32_span){b, 3}), AK_ERR_SPAN_SMALL);
    ak_skeleton_destroy(sk);
}

AK_TEST(desc_rules) {
    ak_skeleton* sk = make_skeleton(1.0f, 0.0f);
    ak_clip* src = make_clip(sk);
    ak_clip* out = NULL;
    ak_retarget_desc zero = {0};
    AK_CHECK_EQ(ak_retarget_clip(&zero, NULL, &out, NULL, NULL), AK_ERR_NULL_ARG);
    ak_retarget_desc r = ak_retarget_desc_resolved(NULL);
    AK_CHECK_NEAR(r.frame_rate, 30.0, 0);
    AK_CHECK_NEAR(r.contact_height, 0.08, 1e-7);
    ak_retarget_desc d = {.source = sk, .clip = src, .target = sk, .frame_rate = -1};
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &out, NULL, NULL), AK_ERR_BAD_ARG);
    int32_t map[NJ];
    for (int i = 0; i < NJ; ++i) map[i] = -1;
    d = (ak_retarget_desc){.source = sk, .clip = src, .target = sk, .source_of_target = {map, NJ}};
    ak_diag diag;
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &out, NULL, &diag), AK_ERR_NOT_FOUND);
    map[3] = NJ;
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &out, NULL, &diag), AK_ERR_BAD_INDEX);
    AK_CHECK(strstr(diag.message, "head") != NULL);
    d.source_of_target.count = 3;
    AK_CHECK_EQ(ak_retarget_clip(&d, NULL, &out, NULL, NULL), AK_ERR_SPAN_SMALL);
    AK_CHECK(out == NULL);
    ak_clip_destroy(src);
    ak_skeleton_destroy(sk);
}

/* Map files: each rule of ak_retarget_map_parse with its exact code and the line named. */
AK_TEST(map_parse) {
    ak_skeleton* sk = make_skeleton(1.0f, 0.0f);
    int32_t map[NJ + 1];
    size_t mapped = 99;
    ak_diag diag;
    const char ok[] = "# target = source\n\n  pelvis\t=  pelvis  # the root\r\nleft_knee=right_knee\nneck = head";
    AK_CHECK_EQ(ak_retarget_map_parse(ok, sizeof ok - 1, sk, sk, (ak_i32_span){map, NJ}, &mapped, &diag), AK_OK);
    AK_CHECK_EQ(mapped, (size_t)3);
    AK_CHECK_EQ(map[0], 0);
    AK_CHECK_EQ(map[11], 14);
    AK_CHECK_EQ(map[2], 3);
    AK_CHECK_EQ(map[1], -1);
    const struct {
        const char* text;
        size_t size; /* 0: strlen */
        ak_result code;
        long line;
        const char* says;
    } bad[] = {
        {"pelvis = pelvis\nneck head\n", 0, AK_ERR_PARSE, 2, "line 2: expected"},
        {"pelvis =\n", 0, AK_ERR_PARSE, 1, "expected"},
        {" = pelvis\n", 0, AK_ERR_PARSE, 1, "expected"},
        {"pelvis = pelvis\nneck = head\0\n", 28, AK_ERR_PARSE, 2, "line 2 holds a NUL byte"},
        {"tail = pelvis\n", 0, AK_ERR_NOT_FOUND, 1, "target has no joint 'tail'"},
        {"pelvis = tail\n", 0, AK_ERR_NOT_FOUND, 1, "source has no joint 'tail'"},
        {"neck = head\n# x\nneck = pelvis\n", 0, AK_ERR_DUPLICATE, 3, "mapped twice"},
        {"# nothing\n\n", 0, AK_ERR_EMPTY, 0, "maps no joint"},
        {"", 0, AK_ERR_EMPTY, 0, "maps no joint"},
        {"pelvis = aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\n", 0, AK_ERR_PARSE, 1,
         "expected"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        size_t n = bad[i].size ? bad[i].size : strlen(bad[i].text);
        mapped = 99;
        ak_result r = ak_retarget_map_parse(bad[i].text, n, sk, sk, (ak_i32_span){map, NJ}, &mapped, &diag);
        AK_CHECK_MSG(r == bad[i].code, "case %zu: %s, want %s", i, ak_result_name(r), ak_result_name(bad[i].code));
        AK_CHECK_MSG(diag.line == bad[i].line && strstr(diag.message, bad[i].says), "case %zu: line %ld: %s", i,
                     diag.line, diag.message);
        AK_CHECK_EQ(mapped, (size_t)0);
        bool cleared = true;
        for (int k = 0; k < NJ; ++k) cleared = cleared && map[k] == -1;
        AK_CHECK_MSG(cleared, "case %zu: the map is not left all -1", i);
    }
    AK_CHECK_EQ(ak_retarget_map_parse(ok, sizeof ok - 1, sk, sk, (ak_i32_span){map, NJ - 1}, NULL, NULL), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_retarget_map_parse(ok, sizeof ok - 1, NULL, sk, (ak_i32_span){map, NJ}, NULL, NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_retarget_map_parse(NULL, 3, sk, sk, (ak_i32_span){map, NJ}, NULL, NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_retarget_map_parse(NULL, 0, sk, sk, (ak_i32_span){map, NJ}, NULL, NULL), AK_ERR_EMPTY);
    ak_skeleton_destroy(sk);
}

/* ---- automatic humanoid mapping ------------------------------------------------------------ */

enum { HJ = 23, QJ = 24 };

/* A humanoid standing at the origin, facing +Z, left at +X (model positions): hips, spine,
 * chest, neck, head, then per side a clavicle, upper arm, forearm, hand, finger, then per side
 * thigh, shin, foot, toe. As in the CMU rigs, clavicle + upper arm (0.24 + 0.30) is longer
 * than upper + lower arm (0.30 + 0.22): only the rule that a short bone (the hand) follows
 * the lower arm tells them apart. */
static const float k_human[HJ][3] = {
    {0, 1, 0},        {0, 1.1f, 0},      {0, 1.3f, 0},     {0, 1.5f, 0},       {0, 1.6f, 0.02f},
    {0.02f, 1.45f, 0}, {0.26f, 1.45f, 0}, {0.56f, 1.45f, 0}, {0.78f, 1.45f, 0}, {0.86f, 1.45f, 0},
    {-0.02f, 1.45f, 0}, {-0.26f, 1.45f, 0}, {-0.56f, 1.45f, 0}, {-0.78f, 1.45f, 0}, {-0.86f, 1.45f, 0},
    {0.1f, 0.95f, 0}, {0.1f, 0.52f, 0.01f}, {0.1f, 0.08f, 0}, {0.1f, 0.02f, 0.12f},
    {-0.1f, 0.95f, 0}, {-0.1f, 0.52f, 0.01f}, {-0.1f, 0.08f, 0}, {-0.1f, 0.02f, 0.12f}};
static const int k_human_parent[HJ] = {-1, 0, 1, 2, 3, 2, 5, 6, 7, 8, 2, 10, 11, 12, 13, 0, 15, 16, 17, 0, 19, 20, 21};
static const char* const k_human_names[HJ] = {
    "Hips",         "Spine",       "Chest",          "Neck",        "Head",        "LeftShoulder", "LeftArm",
    "LeftForeArm",  "LeftHand",    "LeftHandIndex1", "RightShoulder", "RightArm",   "RightForeArm", "RightHand",
    "RightHandIndex1", "LeftUpLeg", "LeftLeg",       "LeftFoot",    "LeftToeBase", "RightUpLeg",  "RightLeg",
    "RightFoot",    "RightToeBase"};
/* The joint each bone must get (-1: none), in ak_humanoid_bone order. */
static const int k_human_roles[AK_BONE_COUNT] = {-1, 0, 1, 2, -1, 3, 4, 5, 6, 7, 8, 10, 11, 12, 13,
                                                 15, 16, 17, 18, 19, 20, 21, 22};

/* A fox-like quadruped facing +Z: hips, spine, chest, neck, head, front legs off the chest,
 * hind legs off the hips, a tail. */
static const float k_quad[QJ][3] = {
    {0, 0.6f, 0},      {0, 0.62f, 0.2f},  {0, 0.62f, 0.5f},  {0, 0.7f, 0.65f},  {0, 0.8f, 0.75f},
    {0.1f, 0.55f, 0.5f}, {0.1f, 0.3f, 0.5f}, {0.1f, 0.05f, 0.5f}, {0.1f, 0, 0.55f},
    {-0.1f, 0.55f, 0.5f}, {-0.1f, 0.3f, 0.5f}, {-0.1f, 0.05f, 0.5f}, {-0.1f, 0, 0.55f},
    {0.1f, 0.55f, 0},  {0.1f, 0.3f, -0.02f}, {0.1f, 0.05f, 0}, {0.1f, 0, 0.05f},
    {-0.1f, 0.55f, 0}, {-0.1f, 0.3f, -0.02f}, {-0.1f, 0.05f, 0}, {-0.1f, 0, 0.05f},
    {0, 0.6f, -0.1f},  {0, 0.55f, -0.3f}, {0, 0.5f, -0.5f}};
static const int k_quad_parent[QJ] = {-1, 0, 1, 2, 3, 2, 5, 6, 7, 2, 9, 10, 11, 0, 13, 14, 15, 0, 17, 18, 19, 0, 21, 22};

/* Skeleton from model positions turned by yaw about +Y (identity rest rotations). names NULL:
 * "bone_0", "bone_1", ...; drop >= 0: that joint and its subtree's toe left out (a leaf). */
static ak_skeleton* make_posed(const float (*pos)[3], const int* parent, int count, const char* const* names, float yaw,
                               int drop) {
    ak_joint_desc j[QJ];
    char nm[QJ][16];
    int index[QJ], n = 0;
    ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), yaw);
    for (int i = 0; i < count; ++i) {
        index[i] = -1;
        if (i == drop) continue;
        ak_vec3 p = ak_quat_rotate(q, ak_vec3_make(pos[i][0], pos[i][1], pos[i][2]));
        if (parent[i] >= 0) {
            ak_vec3 pp = ak_quat_rotate(q, ak_vec3_make(pos[parent[i]][0], pos[parent[i]][1], pos[parent[i]][2]));
            p = ak_vec3_sub(p, pp);
        }
        snprintf(nm[n], sizeof nm[n], "bone_%d", i);
        j[n] = (ak_joint_desc){.name = names ? names[i] : nm[n], .parent = parent[i] >= 0 ? index[parent[i]] : -1,
                               .rest = ak_transform_make(p, ak_quat_identity(), ak_vec3_make(1, 1, 1))};
        index[i] = n++;
    }
    ak_skeleton* s = NULL;
    ak_skeleton_create(&(ak_skeleton_desc){.joints = j, .joint_count = (size_t)n}, NULL, &s, NULL);
    return s;
}

/* Every bone on the joint the table says (indices of the full table; swap: left <-> right). */
static void check_roles(const char* what, const ak_humanoid_roles* r, bool swap) {
    for (int b = 1; b < AK_BONE_COUNT; ++b) {
        int e = b;
        if (swap && b >= AK_BONE_LEFT_SHOULDER && b <= AK_BONE_RIGHT_HAND)
            e = b < AK_BONE_RIGHT_SHOULDER ? b + 4 : b - 4;
        if (swap && b >= AK_BONE_LEFT_UPPER_LEG) e = b < AK_BONE_RIGHT_UPPER_LEG ? b + 4 : b - 4;
        AK_CHECK_MSG(r->joint[b] == k_human_roles[e], "%s: %s on joint %d, expected %d", what, ak_humanoid_bone_name(b),
                     (int)r->joint[b], k_human_roles[e]);
    }
}

AK_TEST(humanoid_roles_template) {
    ak_humanoid_roles r;
    ak_diag diag;
    /* named, facing +Z: every bone, names agree (confidence 1), sides from the toes */
    ak_skeleton* s = make_posed(k_human, k_human_parent, HJ, k_human_names, 0.0f, -1);
    AK_CHECK_EQ(ak_humanoid_roles_find(s, NULL, &r, &diag), AK_OK);
    check_roles("named", &r, false);
    AK_CHECK(r.is_humanoid && r.sides == AK_SIDES_TOES);
    AK_CHECK_MSG(fabsf(r.score - 1.0f) < 1e-6f, "score %g", (double)r.score);
    AK_CHECK(ak_vec3_dot(r.up, ak_vec3_make(0, 1, 0)) > 0.99f && ak_vec3_dot(r.forward, ak_vec3_make(0, 0, 1)) > 0.99f);
    ak_skeleton_destroy(s);
    /* no names, turned to face -Z: topology and geometry alone; the toes say which side is
     * left (the chain now at -X); confidence 0.8 (the names say nothing) */
    s = make_posed(k_human, k_human_parent, HJ, NULL, 3.14159265f, -1);
    AK_CHECK_EQ(ak_humanoid_roles_find(s, NULL, &r, &diag), AK_OK);
    check_roles("anonymous, facing -Z", &r, false);
    AK_CHECK(r.sides == AK_SIDES_TOES && ak_vec3_dot(r.forward, ak_vec3_make(0, 0, -1)) > 0.99f);
    AK_CHECK_MSG(fabsf(r.score - 0.8f) < 1e-6f, "score %g", (double)r.score);
    ak_skeleton_destroy(s);
    /* named, facing -Z, without the left toe: the names decide */
    s = make_posed(k_human, k_human_parent, HJ, k_human_names, 3.14159265f, 18);
    AK_CHECK_EQ(ak_humanoid_roles_find(s, NULL, &r, &diag), AK_OK);
    AK_CHECK_EQ(r.sides, AK_SIDES_NAMES);
    AK_CHECK_EQ(r.joint[AK_BONE_LEFT_UPPER_ARM], ak_skeleton_find_joint(s, "LeftArm"));
    AK_CHECK_EQ(r.joint[AK_BONE_RIGHT_FOOT], ak_skeleton_find_joint(s, "RightFoot"));
    AK_CHECK_EQ(r.joint[AK_BONE_LEFT_TOES], -1);
    ak_skeleton_destroy(s);
    /* neither toes nor names, facing -Z: glTF's +Z convention takes the chain at +X (the
     * right one) for the left: documented, and why a rig without toes needs sided names */
    s = make_posed(k_human, k_human_parent, HJ, NULL, 3.14159265f, 18);
    AK_CHECK_EQ(ak_humanoid_roles_find(s, NULL, &r, &diag), AK_OK);
    AK_CHECK_EQ(r.sides, AK_SIDES_CONVENTION);
    AK_CHECK_EQ(r.joint[AK_BONE_LEFT_UPPER_ARM], ak_skeleton_find_joint(s, "bone_11"));
    ak_skeleton_destroy(s);
    /* the quadruped fits the topology but does not stand */
    s = make_posed(k_quad, k_quad_parent, QJ, NULL, 0.0f, -1);
    memset(&diag, 0, sizeof diag);
    AK_CHECK_EQ(ak_humanoid_roles_find(s, NULL, &r, &diag), AK_ERR_NOT_FOUND);
    AK_CHECK(!r.is_humanoid && r.spine_angle > 60.0f && r.hand_height < -0.8f);
    AK_CHECK_MSG(strstr(diag.message, "not a humanoid") && strstr(diag.message, "quadruped"), "%s", diag.message);
    AK_CHECK_EQ(r.joint[AK_BONE_HIPS], 0);
    ak_skeleton_destroy(s);
    /* a chain: no legs at all */
    s = make_posed(k_human, k_human_parent, 5, NULL, 0.0f, -1);
    AK_CHECK_EQ(ak_humanoid_roles_find(s, NULL, &r, &diag), AK_ERR_NOT_FOUND);
    AK_CHECK_MSG(strstr(diag.message, "no joint has two leg chains") != NULL, "%s", diag.message);
    AK_CHECK_EQ(ak_humanoid_roles_find(NULL, NULL, &r, NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_humanoid_roles_find(s, NULL, NULL, NULL), AK_ERR_NULL_ARG);
    ak_skeleton_destroy(s);
}

/* By roles from an anonymous 23-joint figure onto the named one: every bone pairs with the
 * same table entry; the written map parses back to the same map; a short buffer gets the
 * needed size. Torso pairing: a 1-joint spine drives both target spine joints' ends. */
AK_TEST(map_by_roles_and_write) {
    ak_skeleton* src = make_posed(k_human, k_human_parent, HJ, NULL, 0.0f, -1);
    ak_skeleton* dst = make_posed(k_human, k_human_parent, HJ, k_human_names, 0.0f, -1);
    ak_humanoid_roles sr, tr;
    AK_CHECK_EQ(ak_humanoid_roles_find(src, NULL, &sr, NULL), AK_OK);
    AK_CHECK_EQ(ak_humanoid_roles_find(dst, NULL, &tr, NULL), AK_OK);
    int32_t map[HJ], back[HJ];
    size_t mapped = 0;
    AK_CHECK_EQ(ak_retarget_map_by_roles(src, &sr, dst, &tr, (ak_i32_span){map, HJ}, &mapped), AK_OK);
    AK_CHECK_EQ(mapped, (size_t)21); /* all but the two fingers */
    for (int j = 0; j < HJ; ++j) AK_CHECK_EQ(map[j], j == 9 || j == 14 ? -1 : j);
    size_t need = 0;
    AK_CHECK_EQ(ak_retarget_map_write(src, &sr, dst, &tr, (ak_i32_cspan){map, HJ}, NULL, 0, &need), AK_OK);
    AK_CHECK(need > 100);
    char* text = malloc(need + 1);
    char small[16];
    size_t need2 = 0;
    AK_CHECK_EQ(ak_retarget_map_write(src, &sr, dst, &tr, (ak_i32_cspan){map, HJ}, small, sizeof small, &need2), AK_OK);
    AK_CHECK(need2 == need && small[15] == '\0' && strlen(small) == 15);
    AK_CHECK_EQ(ak_retarget_map_write(src, &sr, dst, &tr, (ak_i32_cspan){map, HJ}, text, need + 1, NULL), AK_OK);
    AK_CHECK_EQ(strlen(text), need);
    AK_CHECK(strstr(text, "LeftArm") && strstr(text, "leftUpperArm"));
    size_t n2 = 0;
    ak_diag diag;
    AK_CHECK_EQ(ak_retarget_map_parse(text, need, src, dst, (ak_i32_span){back, HJ}, &n2, &diag), AK_OK);
    AK_CHECK_EQ(n2, (size_t)21);
    AK_CHECK(memcmp(back, map, sizeof map) == 0);
    free(text);
    /* torso: a source whose spine is one joint (the chest joint dropped: the arms and neck hang
     * from the spine) drives both target torso joints */
    ak_humanoid_roles one = sr;
    one.joint[AK_BONE_CHEST] = -1;
    AK_CHECK_EQ(ak_retarget_map_by_roles(src, &one, dst, &tr, (ak_i32_span){map, HJ}, &mapped), AK_OK);
    AK_CHECK(map[1] == 1 && map[2] == 1);
    /* three target torso joints from two source ones: bottom to bottom, top to top */
    ak_humanoid_roles three = tr;
    three.joint[AK_BONE_UPPER_CHEST] = 3, three.joint[AK_BONE_NECK] = -1;
    AK_CHECK_EQ(ak_retarget_map_by_roles(src, &sr, dst, &three, (ak_i32_span){map, HJ}, &mapped), AK_OK);
    AK_CHECK(map[1] == 1 && map[2] == 2 && map[3] == 2);
    /* bad arguments */
    AK_CHECK_EQ(ak_retarget_map_by_roles(src, &sr, dst, NULL, (ak_i32_span){map, HJ}, NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_retarget_map_by_roles(src, &sr, dst, &tr, (ak_i32_span){map, HJ - 1}, NULL), AK_ERR_SPAN_SMALL);
    three.joint[AK_BONE_HEAD] = HJ;
    AK_CHECK_EQ(ak_retarget_map_by_roles(src, &sr, dst, &three, (ak_i32_span){map, HJ}, NULL), AK_ERR_BAD_INDEX);
    map[0] = HJ;
    AK_CHECK_EQ(ak_retarget_map_write(src, NULL, dst, NULL, (ak_i32_cspan){map, HJ}, NULL, 0, NULL), AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_retarget_map_write(src, NULL, dst, NULL, (ak_i32_cspan){map, HJ - 1}, NULL, 0, NULL), AK_ERR_SPAN_SMALL);
    ak_skeleton_destroy(src);
    ak_skeleton_destroy(dst);
}

int main(void) {
    AK_RUN(identity_on_same_skeleton);
    AK_RUN(uniformly_scaled_copy);
    AK_RUN(rest_pose_arms_turned_45_degrees);
    AK_RUN(bone_names);
    AK_RUN(desc_rules);
    AK_RUN(map_parse);
    AK_RUN(humanoid_roles_template);
    AK_RUN(map_by_roles_and_write);
    return ak_test_finish();
}
