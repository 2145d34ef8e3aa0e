/* animkit ik on the command line: the default chain (the limb, never a plain node above the
 * skeleton), the straight arm of builtin:humanoid with targets on its own line, and --json
 * that always parses, at any scale. Oracles: the models' hierarchies as `info` prints them,
 * closed forms (the law of cosines for the arm's reach under its elbow limit), and geometry
 * recomputed here from the printed positions. */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include "ak_test.h"
#include "cli_test.h"

/* Run with --json; the output must parse (NULL otherwise, with a failed check). */
static cJSON* run_json(const char* args) {
    int rc = run(args, false);
    AK_CHECK_MSG(rc == 0, "'%s' exit %d", args, rc);
    if (rc != 0) return NULL;
    cJSON* root = cJSON_Parse(out_buf);
    AK_CHECK_MSG(root != NULL, "'%s' printed invalid JSON: %s", args, out_buf);
    return root;
}

static const char* joint_name(const cJSON* root, const char* set, int i) {
    const cJSON* j = cJSON_GetArrayItem(cJSON_GetObjectItem(root, set), i);
    const cJSON* n = cJSON_GetObjectItem(j, "name");
    return cJSON_IsString(n) ? n->valuestring : "";
}

static double joint_coord(const cJSON* root, const char* set, int i, int c) {
    const cJSON* j = cJSON_GetArrayItem(cJSON_GetObjectItem(root, set), i);
    const cJSON* v = cJSON_GetArrayItem(cJSON_GetObjectItem(j, "position"), c);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

/* The chain in "joints" is exactly want[0..count). */
static void check_chain(const cJSON* root, const char* const* want, int count, const char* what) {
    const int n = cJSON_GetArraySize(cJSON_GetObjectItem(root, "joints"));
    AK_CHECK_MSG(n == count, "%s: chain of %d joints, want %d", what, n, count);
    for (int i = 0; i < n && i < count; ++i)
        AK_CHECK_MSG(strcmp(joint_name(root, "joints", i), want[i]) == 0, "%s: joint %d is '%s', want '%s'", what, i,
                     joint_name(root, "joints", i), want[i]);
}

/* The default chain is the limb the effector ends: up through the skin's joints, stopping
 * below the first joint with several child joints. builtin:humanoid (from `info`): spine_02
 * carries neck and both shoulders, pelvis carries spine_01 and both hips. CesiumMan: the
 * nodes Z_UP and Armature sit above the joints; torso_joint_3 carries both arms and the
 * neck, Skeleton_torso_joint_1 both legs and the spine. */
AK_TEST(ik_default_chain_is_the_limb) {
    static const char* const arm[] = {"left_shoulder", "left_elbow", "left_wrist"};
    static const char* const leg[] = {"left_hip", "left_knee", "left_ankle"};
    static const char* const head[] = {"neck", "head"};
    cJSON* root = run_json("ik builtin:humanoid --effector left_wrist --target 0.45,1.0,0.25 --json");
    if (root) check_chain(root, arm, 3, "humanoid left_wrist");
    cJSON_Delete(root);
    root = run_json("ik builtin:humanoid --effector left_ankle --target 0.1,0.3,0.2 --json");
    if (root) check_chain(root, leg, 3, "humanoid left_ankle");
    cJSON_Delete(root);
    root = run_json("ik builtin:humanoid --effector head --target 0,1.7,0.1 --json");
    if (root) check_chain(root, head, 2, "humanoid head");
    cJSON_Delete(root);
    /* the text output names the chain it used */
    AK_CHECK_EQ(run("ik builtin:humanoid --effector left_wrist --target 0.45,1.0,0.25", false), 0);
    AK_CHECK_MSG(strstr(out_buf, "chain (3 joints, default root") &&
                     strstr(out_buf, "left_shoulder -> left_elbow -> left_wrist"),
                 "text output does not name the chain: %s", out_buf);
    /* --root still wins */
    root = run_json("ik builtin:humanoid --effector left_wrist --root spine_01 --target 0.45,1.0,0.25 --json");
    if (root) AK_CHECK_STREQ(joint_name(root, "joints", 0), "spine_01");
    cJSON_Delete(root);

    char path[1200], args[1600];
    if (!ak_test_asset(path, sizeof path, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb")) {
        AK_SKIP("CesiumMan.glb absent (set ANIMKIT_ASSETS)");
        return;
    }
    static const char* const cesium_arm[] = {"Skeleton_arm_joint_L__4_", "Skeleton_arm_joint_L__3_",
                                             "Skeleton_arm_joint_L__2_"};
    static const char* const cesium_leg[] = {"leg_joint_L_1", "leg_joint_L_2", "leg_joint_L_3", "leg_joint_L_5"};
    /* the command: the chain used to start at Z_UP and tip the whole body over */
    snprintf(args, sizeof args, "ik '%s' --effector Skeleton_arm_joint_L__2_ --target 0.3,0.3,1.2 --json", path);
    root = run_json(args);
    if (root) {
        check_chain(root, cesium_arm, 3, "CesiumMan arm");
        /* the chain root stays where it was: the body does not move */
        for (int c = 0; c < 3; ++c)
            AK_CHECK_NEAR(joint_coord(root, "joints", 0, c), joint_coord(root, "initial", 0, c), 1e-6);
    }
    cJSON_Delete(root);
    snprintf(args, sizeof args, "ik '%s' --effector leg_joint_L_5 --target 0.1,0.3,0.2 --json", path);
    root = run_json(args);
    if (root) {
        check_chain(root, cesium_leg, 4, "CesiumMan leg");
        AK_CHECK(cJSON_IsTrue(cJSON_GetObjectItem(root, "reached")));
    }
    cJSON_Delete(root);
    snprintf(args, sizeof args, "ik '%s' --effector Skeleton_arm_joint_L__2_ --target 0.3,0.3,1.2", path);
    AK_CHECK_EQ(run(args, false), 0);
    AK_CHECK_MSG(strstr(out_buf, "Skeleton_arm_joint_L__4_ -> Skeleton_arm_joint_L__3_ -> Skeleton_arm_joint_L__2_") &&
                     !strstr(out_buf, "Z_UP"),
                 "text output: %s", out_buf);
}

/* builtin:humanoid's left arm rests straight (A-pose): shoulder (0.19, 1.42, 0), bones 0.28
 * and 0.26 along (1, -1, 0) / sqrt 2, elbow a hinge limited to [0, 145] degrees. Targets on
 * the arm's own line are reachable from a = 0.28 + 0.26 down to the elbow's limit,
 * sqrt(a^2 + b^2 - 2 a b cos 35deg) = 0.1635 (30% of the reach); each solver must reach the
 * ones at 35..95% from the straight arm, and ones a few last digits off the line. The target (0.2, 1.4, 0) lies 0.0224 from
 * the shoulder, inside that limit: no pose within the limits reaches it, and the best is
 * 0.1635 - 0.0224 = 0.14114 away; CCD finds that best, and no solver may claim better. */
AK_TEST(ik_straight_arm_targets_on_its_line) {
    const double a = 0.28, b = 0.26, c45 = sqrt(0.5);
    const char* solvers[] = {"ccd", "fabrik", "dls"};
    for (int s = 0; s < 3; ++s) {
        for (int pct = 35; pct <= 95; pct += 10) {
            const double d = (a + b) * pct / 100.0;
            char args[512];
            snprintf(args, sizeof args,
                     "ik builtin:humanoid --effector left_wrist --root left_shoulder --target %.9g,%.9g,0 --solver %s "
                     "--json",
                     0.19 + c45 * d, 1.42 - c45 * d, solvers[s]);
            cJSON* root = run_json(args);
            if (!root) continue;
            const cJSON* err = cJSON_GetObjectItem(root, "error");
            AK_CHECK_MSG(cJSON_IsTrue(cJSON_GetObjectItem(root, "reached")), "%s at %d%%: not reached, error %g",
                         solvers[s], pct, cJSON_IsNumber(err) ? err->valuedouble : -1.0);
            cJSON_Delete(root);
        }
    }
    /* Near the line (issue 27): 5% in from the wrist, 1e-5 off the line (every solver stopped
     * 0.027 away, the arm straight and pointing at it), the same rounded to 4 digits, and
     * points at 56% and 73% of the reach a few last digits off. */
    const char* near[] = {"0.552754,1.057246,0.00001", "0.5527,1.0573,0.0001", "0.4040,1.2060,-0.0003",
                          "0.46831,1.14169,0.000007"};
    for (int s = 0; s < 3; ++s) {
        for (size_t k = 0; k < sizeof near / sizeof near[0]; ++k) {
            char args[512];
            snprintf(args, sizeof args,
                     "ik builtin:humanoid --effector left_wrist --root left_shoulder --target %s --solver %s --json",
                     near[k], solvers[s]);
            cJSON* root = run_json(args);
            if (!root) continue;
            const cJSON* err = cJSON_GetObjectItem(root, "error");
            AK_CHECK_MSG(cJSON_IsTrue(cJSON_GetObjectItem(root, "reached")), "%s at %s: not reached, error %g", solvers[s],
                         near[k], cJSON_IsNumber(err) ? err->valuedouble : -1.0);
            cJSON_Delete(root);
        }
    }
    const double shoulder[3] = {0.19, 1.42, 0.0}, target[3] = {0.2, 1.4, 0.0};
    const double reach_min = sqrt(a * a + b * b - 2 * a * b * cos(35.0 * 3.14159265358979323846 / 180.0));
    const double best = reach_min - hypot(target[0] - shoulder[0], target[1] - shoulder[1]);
    const char* all[] = {"ccd", "fabrik", "dls", "twobone"};
    for (int s = 0; s < 4; ++s) {
        char args[512];
        snprintf(args, sizeof args,
                 "ik builtin:humanoid --effector left_wrist --root left_shoulder --target 0.2,1.4,0 --solver %s --json",
                 all[s]);
        cJSON* root = run_json(args);
        if (!root) continue;
        const cJSON* err = cJSON_GetObjectItem(root, "error");
        AK_CHECK(cJSON_IsFalse(cJSON_GetObjectItem(root, "reached")));
        AK_CHECK_MSG(cJSON_IsNumber(err) && err->valuedouble >= best - 1e-5, "%s: error %g below the bound %g", all[s],
                     cJSON_IsNumber(err) ? err->valuedouble : -1.0, best);
        if (s == 0) AK_CHECK_NEAR(err->valuedouble, best, 1e-5);
        cJSON_Delete(root);
    }
}

/* A chain of 1e30-long bones (a plain node chain in a .gltf written here): the solvers run
 * at any scale, --json parses and holds finite numbers, reached is honest. Bones of 3e38
 * overflow float on the way to model space: exit 1 with a message, not "inf". */
AK_TEST(ik_json_valid_at_extreme_scales) {
    const char* doc =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":["
        "{\"name\":\"root\",\"children\":[1]},{\"name\":\"a\",\"translation\":[%s,0,0],\"children\":[2]},"
        "{\"name\":\"b\",\"translation\":[%s,0,0],\"children\":[3]},{\"name\":\"c\",\"translation\":[%s,0,0]}]}";
    const char* sizes[] = {"1e30", "3e38"};
    for (int k = 0; k < 2; ++k) {
        char name[32];
        snprintf(name, sizeof name, "bones_%s.gltf", sizes[k]);
        FILE* f = fopen(name, "wb");
        AK_CHECK(f != NULL);
        if (!f) return;
        fprintf(f, doc, sizes[k], sizes[k], sizes[k]);
        fclose(f);
    }
    const char* solvers[] = {"ccd", "fabrik", "dls"};
    for (int s = 0; s < 3; ++s) {
        for (int far = 0; far < 2; ++far) {
            char args[512];
            snprintf(args, sizeof args, "ik bones_1e30.gltf --effector c --target %s --solver %s --json",
                     far ? "9e30,0,0" : "1e30,1.2e30,0", solvers[s]);
            cJSON* root = run_json(args);
            if (!root) continue;
            AK_CHECK_MSG(!strstr(out_buf, "inf") && !strstr(out_buf, "nan"), "%s", out_buf);
            const cJSON* err = cJSON_GetObjectItem(root, "error");
            const bool reached = cJSON_IsTrue(cJSON_GetObjectItem(root, "reached"));
            AK_CHECK_MSG(cJSON_IsNumber(err) && isfinite(err->valuedouble), "'%s': error not a finite number", args);
            /* the printed error is the distance from the printed effector to the target */
            const double t[3] = {far ? 9e30 : 1e30, far ? 0 : 1.2e30, 0};
            double e2 = 0;
            for (int c = 0; c < 3; ++c) e2 += (joint_coord(root, "joints", 3, c) - t[c]) * (joint_coord(root, "joints", 3, c) - t[c]);
            if (cJSON_IsNumber(err)) AK_CHECK_NEAR(err->valuedouble, sqrt(e2), 1e-5 * 3e30);
            if (far) {
                AK_CHECK_MSG(!reached, "'%s': an unreachable target reported reached", args);
                if (cJSON_IsNumber(err)) AK_CHECK_NEAR(err->valuedouble, 6e30, 1e-4 * 6e30);
            } else {
                AK_CHECK_MSG(reached, "'%s': not reached", args);
                if (cJSON_IsNumber(err)) AK_CHECK(err->valuedouble <= 1e-4 * 3e30);
            }
            cJSON_Delete(root);
        }
    }
    const int rc = run("ik bones_3e38.gltf --effector c --target 1,0,0 --json", true);
    AK_CHECK_MSG(rc == 1 && strstr(out_buf, "bones_3e38.gltf") && !strstr(out_buf, "\"error\""), "exit %d: %s", rc, out_buf);
    /* targets beyond +-1e37 are bad usage */
    AK_CHECK_EQ(run("ik bones_1e30.gltf --effector c --target 3e38,0,0 --json", true), 2);
}

/* --target is exactly three numbers: an empty or trailing component is bad usage, not skipped;
 * --iterations names its range */
AK_TEST(ik_target_and_iterations_usage) {
    const char* bad[] = {"1,,2,3", "1,2,3,", ",1,2,3", "1,2,,", "1,2,3,4"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        char args[160];
        snprintf(args, sizeof args, "ik builtin:humanoid --effector left_wrist --target '%s'", bad[i]);
        AK_CHECK_MSG(run(args, true) == 2 && strstr(out_buf, "three numbers"), "%s: %s", args, out_buf);
    }
    AK_CHECK_EQ(run("ik builtin:humanoid --effector left_wrist --target ' 0.4, 1, 0.2'", true), 0);
    AK_CHECK(run("ik builtin:humanoid --effector left_wrist --target 0.4,1,0.2 --iterations 2000000", true) == 2 &&
             strstr(out_buf, "1..1000000"));
}

int main(void) {
    AK_RUN_SLOW(ik_default_chain_is_the_limb);
    AK_RUN_SLOW(ik_straight_arm_targets_on_its_line);
    AK_RUN(ik_json_valid_at_extreme_scales);
    AK_RUN(ik_target_and_iterations_usage);
    return ak_test_finish();
}
