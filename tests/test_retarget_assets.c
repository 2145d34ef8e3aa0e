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
    ak_i16_cspan tp = ak_skeleton_parents(ts);
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


#ifdef AK_CLI_PATH
/* Lines the last run_cli printed on stderr. */
static int g_cli_lines;

/* Run the CLI; returns the exit status and the first line of stderr in line. */
static int run_cli(const char* args, char* line, size_t n) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "'%s' retarget %s 2>&1 >/dev/null", AK_CLI_PATH, args);
    FILE* p = popen(cmd, "r");
    if (!p) return -1;
    line[0] = '\0';
    char buf[1024];
    int lines = 0;
    while (fgets(buf, sizeof buf, p))
        if (lines++ == 0) snprintf(line, n, "%s", buf);
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
    /* no name in common: exit 1, one line naming the target */
    snprintf(args, sizeof args, "'%s' '%s' -o '%s'", bvh, cesium, out);
    AK_CHECK_EQ(run_cli(args, line, sizeof line), 1);
    AK_CHECK(strstr(line, "CesiumMan.glb") && strstr(line, "--map"));
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
#ifdef AK_CLI_PATH
    AK_RUN(cli_exports_stand_on_the_floor);
    AK_RUN(cli_gif_frames_each_figure);
    AK_RUN_SLOW(cli_retarget);
#endif
    return ak_test_finish();
}
