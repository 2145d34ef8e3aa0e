/* The animkit command: exit codes, JSON contracts, outputs checked against independent
 * computations (the library's data read back, double-precision skinning in the test). */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include <sys/stat.h>

#include "ak_test.h"
#include "cli_test.h"
#include "ref/ref_gif.h" /* GIF frame delays read straight from the file */
#include "ref/ref_gltf.h"

static cJSON* run_json(const char* args) {
    if (run(args, false) != 0) return NULL;
    return cJSON_Parse(out_buf);
}

AK_TEST(usage_and_help) {
    AK_CHECK_EQ(run("", true), 2);
    AK_CHECK_EQ(run("help", true), 0);
    AK_CHECK(strstr(out_buf, "render") && strstr(out_buf, "demo"));
    AK_CHECK_EQ(run("frobnicate", true), 2);
    const char* cmds[] = {"demo", "info", "export", "render", "curves", "weights", "skin", "ik"};
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; ++i) {
        char a[64];
        snprintf(a, sizeof a, "%s --help", cmds[i]);
        AK_CHECK_MSG(run(a, true) == 0 && strstr(out_buf, "usage: animkit"), "%s --help", cmds[i]);
        snprintf(a, sizeof a, "help %s", cmds[i]);
        AK_CHECK_MSG(run(a, true) == 0, "help %s", cmds[i]);
        snprintf(a, sizeof a, "%s --no-such-flag x", cmds[i]);
        AK_CHECK_MSG(run(a, true) == 2, "%s unknown flag", cmds[i]);
    }
}

AK_TEST(bad_input_paths) {
    /* missing file, directory, garbage file, unknown builtin: exit 1 and one line naming it */
    const char* subs[] = {"info %s", "export %s -o x.obj", "render %s -o x.png", "curves %s --clip 0 -o x.png",
                          "weights %s --method distance -o w.json", "ik %s --effector a --target 0,0,0",
                          "skin --compare %s"};
    FILE* f = fopen("garbage.gltf", "wb");
    AK_CHECK(f != NULL);
    if (f) {
        fputs("{ this is not json", f);
        fclose(f);
    }
    const char* inputs[] = {"no_such_file.glb", ".", "garbage.gltf", "builtin:nope"};
    for (size_t s = 0; s < sizeof subs / sizeof subs[0]; ++s) {
        for (size_t i = 0; i < sizeof inputs / sizeof inputs[0]; ++i) {
            char a[256];
            snprintf(a, sizeof a, subs[s], inputs[i]);
            int rc = run(a, true);
            AK_CHECK_MSG(rc == 1, "'%s' exit %d (want 1): %s", a, rc, out_buf);
            AK_CHECK_MSG(strstr(out_buf, inputs[i]) != NULL, "'%s' message does not name the input: %s", a, out_buf);
            const char* nl = strchr(out_buf, '\n');
            AK_CHECK_MSG(nl && nl[1] == '\0', "'%s' should print exactly one line: %s", a, out_buf);
        }
    }
    /* unknown joint, bad numbers, unknown clip */
    AK_CHECK_EQ(run("ik builtin:humanoid --effector no_joint --target 0,1,0", true), 1);
    AK_CHECK(strstr(out_buf, "no_joint") != NULL);
    AK_CHECK_EQ(run("ik builtin:humanoid --effector left_wrist --target 0,abc,0", true), 2);
    AK_CHECK_EQ(run("ik builtin:humanoid --effector left_wrist --target 0,1", true), 2);
    AK_CHECK_EQ(run("ik builtin:humanoid --effector left_wrist --target 0,1,0 --iterations -3", true), 2);
    AK_CHECK_EQ(run("export builtin:cylinder --time nan -o x.obj", true), 2);
    AK_CHECK_EQ(run("export builtin:cylinder --time 1e99 -o x.obj", true), 2);
    AK_CHECK_EQ(run("export builtin:cylinder --clip nope -o x.obj", true), 1);
    AK_CHECK(strstr(out_buf, "nope") != NULL);
    AK_CHECK_EQ(run("export builtin:cylinder", true), 2);
    AK_CHECK_EQ(run("export builtin:cylinder -o x.txt", true), 2);
    AK_CHECK_EQ(run("render builtin:cylinder --size 0x0 -o x.png", true), 2);
    AK_CHECK_EQ(run("render builtin:cylinder --weights nobone -o x.png", true), 1);
    AK_CHECK_EQ(run("render builtin:cylinder --method xyz -o x.png", true), 2);
    AK_CHECK_EQ(run("render builtin:cylinder --frames 1:0:0 -o x.gif", true), 2);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --joint nobody -o c.png", true), 1);
    AK_CHECK_EQ(run("weights builtin:cylinder --method magic -o w.json", true), 2);
    AK_CHECK_EQ(run("weights builtin:cylinder --method distance --power -1 -o w.json", true), 2);
    AK_CHECK_EQ(run("skin", true), 2);
    /* a target far beyond float range for squared distances: bad usage, or valid JSON with a
     * finite error (never "inf" or "nan" in the output) */
    const char* far[] = {"1e30,0,0", "3e38,3e38,-3e38", "1e20,0,1e20"};
    for (size_t i = 0; i < sizeof far / sizeof far[0]; ++i) {
        char a[160];
        snprintf(a, sizeof a, "ik builtin:humanoid --effector left_wrist --target %s --json", far[i]);
        int rc = run(a, false);
        if (rc == 0) {
            cJSON* root = cJSON_Parse(out_buf);
            const cJSON* err = cJSON_GetObjectItem(root, "error");
            AK_CHECK_MSG(cJSON_IsNumber(err) && isfinite(err->valuedouble), "'%s' printed %s", a, out_buf);
            cJSON_Delete(root);
        } else {
            AK_CHECK_MSG(rc == 2, "'%s' exit %d", a, rc);
        }
    }
}

static int find_joint_json(cJSON* joints, const char* name) {
    int i = 0;
    cJSON* j;
    cJSON_ArrayForEach(j, joints) {
        if (strcmp(cJSON_GetObjectItem(j, "name")->valuestring, name) == 0) return i;
        ++i;
    }
    return -1;
}

AK_TEST(info_json_contract) {
    cJSON* root = run_json("info builtin:humanoid --json");
    AK_CHECK(root != NULL);
    if (!root) return;
    cJSON* joints = cJSON_GetObjectItem(root, "joints");
    cJSON* meshes = cJSON_GetObjectItem(root, "meshes");
    cJSON* clips = cJSON_GetObjectItem(root, "clips");
    AK_CHECK(cJSON_IsArray(joints) && cJSON_IsArray(meshes) && cJSON_IsArray(clips));
    AK_CHECK(cJSON_GetArraySize(joints) >= 17);
    /* compare with the library's own scene (what the command must report) */
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_builtin_create("builtin:humanoid", NULL, NULL, &s), AK_OK);
    if (s) {
        AK_CHECK_EQ(cJSON_GetArraySize(joints), (int)ak_scene_joint_count(s));
        AK_CHECK_EQ(cJSON_GetArraySize(meshes), (int)s->mesh_count);
        AK_CHECK_EQ(cJSON_GetArraySize(clips), (int)s->clip_count);
        cJSON* m0 = cJSON_GetArrayItem(meshes, 0);
        AK_CHECK_EQ(cJSON_GetObjectItem(m0, "vertices")->valueint, (int)s->meshes[0].mesh->vertex_count);
        AK_CHECK_EQ(cJSON_GetObjectItem(m0, "triangles")->valueint, (int)s->meshes[0].mesh->triangle_count);
        AK_CHECK(cJSON_IsTrue(cJSON_GetObjectItem(m0, "skinned")));
        AK_CHECK_EQ(cJSON_GetObjectItem(m0, "morph_targets")->valueint, 0);
        for (size_t c = 0; c < s->clip_count; ++c) {
            cJSON* cj = cJSON_GetArrayItem(clips, (int)c);
            AK_CHECK_STREQ(cJSON_GetObjectItem(cj, "name")->valuestring, ak_clip_name(s->clips[c]));
            AK_CHECK_NEAR(cJSON_GetObjectItem(cj, "duration")->valuedouble, ak_clip_duration(s->clips[c]), 1e-6);
            AK_CHECK_EQ(cJSON_GetObjectItem(cj, "channels")->valueint, (int)ak_clip_channel_count(s->clips[c]));
        }
        ak_scene_destroy(s);
    }
    int elbow = find_joint_json(joints, "left_elbow"), shoulder = find_joint_json(joints, "left_shoulder");
    AK_CHECK(elbow >= 0 && shoulder >= 0);
    if (elbow >= 0)
        AK_CHECK_EQ(cJSON_GetObjectItem(cJSON_GetArrayItem(joints, elbow), "parent")->valueint, shoulder);
    AK_CHECK_EQ(cJSON_GetObjectItem(cJSON_GetArrayItem(joints, 0), "parent")->valueint, -1);
    cJSON_Delete(root);
}

/* info --json on every glTF asset against the file's JSON read here: mesh entries (one per
 * primitive and instancing node) with their vertex counts, clips with their names, the
 * channel count the file declares and the largest sampler input max as duration. */
AK_TEST(info_json_matches_gltf_files) {
    char dir[1100];
    if (!ak_test_asset(dir, sizeof dir, "gltf")) {
        AK_SKIP("no assets (set ANIMKIT_ASSETS or put them in ../shared/assets)");
        return;
    }
    const char* files[] = {"RiggedSimple/glTF/RiggedSimple.gltf", "CesiumMan/glTF-Binary/CesiumMan.glb",
                           "Fox/glTF-Binary/Fox.glb", "SimpleSkin/glTF/SimpleSkin.gltf",
                           "SimpleMorph/glTF/SimpleMorph.gltf", "AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb",
                           "MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf",
                           "MorphStressTest/glTF-Binary/MorphStressTest.glb"};
    for (size_t f = 0; f < sizeof files / sizeof files[0]; ++f) {
        char path[1300], args[1500];
        snprintf(path, sizeof path, "%s/%s", dir, files[f]);
        snprintf(args, sizeof args, "info '%s' --json", path);
        cJSON* root = run_json(args);
        doc d;
        bool opened = doc_open(&d, path);
        AK_CHECK_MSG(root && opened, "%s: info or reference reader failed", files[f]);
        if (!root || !opened) {
            cJSON_Delete(root);
            if (opened) doc_close(&d);
            continue;
        }
        const cJSON* meshes = cJSON_GetObjectItem(root, "meshes");
        int at = 0;
        for (int mi = 0; mi < jsize(d.root, "meshes"); ++mi) {
            const cJSON* prims = jget(jat(d.root, "meshes", mi), "primitives");
            int users = 0;
            for (int ni = 0; ni < jsize(d.root, "nodes"); ++ni) users += jint(jat(d.root, "nodes", ni), "mesh", -1) == mi;
            for (int u = 0; u < (users ? users : 1); ++u)
                for (int pi = 0; pi < cJSON_GetArraySize(prims); ++pi, ++at) {
                    int pa = jint(jget(cJSON_GetArrayItem(prims, pi), "attributes"), "POSITION", -1);
                    const cJSON* mj = cJSON_GetArrayItem(meshes, at);
                    AK_CHECK_MSG(mj && cJSON_GetObjectItem(mj, "vertices")->valueint == accessor_count(&d, pa),
                                 "%s: mesh entry %d vertices", files[f], at);
                }
        }
        AK_CHECK_MSG(cJSON_GetArraySize(meshes) == at, "%s: %d mesh entries, want %d", files[f],
                     cJSON_GetArraySize(meshes), at);
        const cJSON* clips = cJSON_GetObjectItem(root, "clips");
        AK_CHECK_MSG(cJSON_GetArraySize(clips) == jsize(d.root, "animations"), "%s: clip count", files[f]);
        for (int ai = 0; ai < jsize(d.root, "animations") && ai < cJSON_GetArraySize(clips); ++ai) {
            const cJSON* an = jat(d.root, "animations", ai);
            const cJSON* cj = cJSON_GetArrayItem(clips, ai);
            int file_channels = jsize(an, "channels");
            int got = cJSON_GetObjectItem(cj, "channels")->valueint;
            AK_CHECK_MSG(got == file_channels, "%s: animations[%d] has %d channels, info says %d", files[f], ai,
                         file_channels, got);
            double dur = 0;
            for (int si = 0; si < jsize(an, "samplers"); ++si) {
                const cJSON* acc = jat(d.root, "accessors", jint(jat(an, "samplers", si), "input", -1));
                dur = fmax(dur, cJSON_GetArrayItem(jget(acc, "max"), 0)->valuedouble);
            }
            AK_CHECK_NEAR(cJSON_GetObjectItem(cj, "duration")->valuedouble, dur, 1e-6);
            const cJSON* name = jget(an, "name");
            char want[64];
            snprintf(want, sizeof want, "animation_%d", ai);
            AK_CHECK_STREQ(cJSON_GetObjectItem(cj, "name")->valuestring,
                           cJSON_IsString(name) && name->valuestring[0] ? name->valuestring : want);
        }
        doc_close(&d);
        cJSON_Delete(root);
    }
}

/* Read the "v" lines of an OBJ file. */
static size_t read_obj_vertices(const char* path, ak_vec3* out, size_t cap, size_t* out_groups) {
    FILE* f = fopen(path, "r");
    size_t n = 0;
    *out_groups = 0;
    if (!f) return 0;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        float x, y, z;
        if (line[0] == 'o' && line[1] == ' ') ++*out_groups;
        if (line[0] == 'v' && line[1] == ' ' && sscanf(line + 2, "%f %f %f", &x, &y, &z) == 3 && n < cap)
            out[n++] = ak_vec3_make(x, y, z);
    }
    fclose(f);
    return n;
}

AK_TEST(export_matches_double_precision_skinning) {
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_builtin_create("builtin:cylinder", NULL, NULL, &s), AK_OK);
    if (!s) return;
    const ak_mesh* mesh = s->meshes[0].mesh;
    size_t vc = mesh->vertex_count;
    ak_vec3* v = calloc(vc + 16, sizeof(ak_vec3));
    size_t groups = 0;
    /* --bind writes the stored positions */
    AK_CHECK_EQ(run("export builtin:cylinder --bind -o bind.obj", true), 0);
    AK_CHECK_EQ(read_obj_vertices("bind.obj", v, vc + 16, &groups), (long long)vc);
    AK_CHECK_EQ(groups, 1);
    double worst = 0.0;
    for (size_t i = 0; i < vc; ++i) worst = fmax(worst, ak_vec3_distance(v[i], mesh->positions[i]));
    AK_CHECK_NEAR(worst, 0.0, 1e-6);
    /* bend clip at 0.5 s: LBS in double from the clip's pose */
    int clip = ak_scene_find_clip(s, "bend");
    AK_CHECK(clip >= 0);
    size_t n = ak_scene_joint_count(s);
    ak_transform local[16];
    ak_mat4 world[16];
    ak_scene_rest_pose(s, (ak_transform_span){local, n});
    ak_clip_sample(s->clips[clip], 0.5f, NULL, (ak_transform_span){local, n}, (ak_f32_span){0}, (ak_f32_span){0});
    /* world matrices in double, by walking the parents */
    double W[16][16];
    ak_i32_cspan par = ak_skeleton_parents(s->skeleton);
    for (size_t j = 0; j < n; ++j) {
        ak_mat4 lm = ak_transform_to_mat4(local[j]);
        double L[16];
        for (int e = 0; e < 16; ++e) L[e] = lm.m[e];
        if (par.ptr[j] < 0) {
            memcpy(W[j], L, sizeof L);
        } else {
            const double* P = W[par.ptr[j]];
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) {
                    double acc = 0;
                    for (int k = 0; k < 4; ++k) acc += P[k * 4 + r] * L[c * 4 + k];
                    W[j][c * 4 + r] = acc;
                }
        }
    }
    (void)world;
    AK_CHECK_EQ(run("export builtin:cylinder --clip bend --time 0.5 -o bend.obj", true), 0);
    AK_CHECK_EQ(read_obj_vertices("bend.obj", v, vc + 16, &groups), (long long)vc);
    const ak_scene_skin* sk = &s->skins[0];
    worst = 0.0;
    for (size_t i = 0; i < vc; ++i) {
        double acc[3] = {0, 0, 0};
        for (uint32_t k = 0; k < mesh->influence_count; ++k) {
            double w = mesh->weights[i * mesh->influence_count + k];
            size_t slot = mesh->joints[i * mesh->influence_count + k];
            const double* M = W[sk->joints[slot]];
            const float* B = sk->inverse_binds[slot].m;
            double p[4] = {mesh->positions[i].x, mesh->positions[i].y, mesh->positions[i].z, 1.0}, q[4];
            for (int r = 0; r < 4; ++r) q[r] = B[r] * p[0] + B[4 + r] * p[1] + B[8 + r] * p[2] + B[12 + r] * p[3];
            for (int r = 0; r < 3; ++r) acc[r] += w * (M[r] * q[0] + M[4 + r] * q[1] + M[8 + r] * q[2] + M[12 + r] * q[3]);
        }
        double d = sqrt((acc[0] - v[i].x) * (acc[0] - v[i].x) + (acc[1] - v[i].y) * (acc[1] - v[i].y) +
                        (acc[2] - v[i].z) * (acc[2] - v[i].z));
        worst = fmax(worst, d);
    }
    AK_CHECK_NEAR(worst, 0.0, 1e-5);
    free(v);
    ak_scene_destroy(s);
}

AK_TEST(ik_json_contract) {
    cJSON* root = run_json("ik builtin:humanoid --effector left_wrist --root left_shoulder --target 0.45,1.0,0.25 --json");
    AK_CHECK(root != NULL);
    if (!root) return;
    AK_CHECK(cJSON_IsBool(cJSON_GetObjectItem(root, "reached")));
    AK_CHECK(cJSON_IsNumber(cJSON_GetObjectItem(root, "error")));
    AK_CHECK(cJSON_IsNumber(cJSON_GetObjectItem(root, "iterations")));
    cJSON* joints = cJSON_GetObjectItem(root, "joints");
    cJSON* initial = cJSON_GetObjectItem(root, "initial");
    AK_CHECK(cJSON_GetArraySize(joints) == 3 && cJSON_GetArraySize(initial) == 3);
    AK_CHECK_STREQ(cJSON_GetObjectItem(cJSON_GetArrayItem(joints, 0), "name")->valuestring, "left_shoulder");
    AK_CHECK_STREQ(cJSON_GetObjectItem(cJSON_GetArrayItem(joints, 2), "name")->valuestring, "left_wrist");
    /* the root stays put, bone lengths are kept, and the error is the effector's distance */
    double p[2][3][3];
    for (int set = 0; set < 2; ++set)
        for (int i = 0; i < 3; ++i)
            for (int c = 0; c < 3; ++c)
                p[set][i][c] = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetArrayItem(set ? initial : joints, i), "position"), c)->valuedouble;
    for (int c = 0; c < 3; ++c) AK_CHECK_NEAR(p[0][0][c], p[1][0][c], 1e-6);
    for (int i = 0; i < 2; ++i) {
        double l0 = 0, l1 = 0;
        for (int c = 0; c < 3; ++c) {
            l0 += (p[0][i + 1][c] - p[0][i][c]) * (p[0][i + 1][c] - p[0][i][c]);
            l1 += (p[1][i + 1][c] - p[1][i][c]) * (p[1][i + 1][c] - p[1][i][c]);
        }
        AK_CHECK_NEAR(sqrt(l0), sqrt(l1), 1e-5 * sqrt(l1));
    }
    double t[3] = {0.45, 1.0, 0.25}, e = 0;
    for (int c = 0; c < 3; ++c) e += (p[0][2][c] - t[c]) * (p[0][2][c] - t[c]);
    AK_CHECK_NEAR(sqrt(e), cJSON_GetObjectItem(root, "error")->valuedouble, 1e-5);
    cJSON_Delete(root);
    /* an unreachable target: reached false, chain straightened (error = distance - reach) */
    root = run_json("ik builtin:humanoid --effector left_wrist --root left_shoulder --target 5,1.4,0 --solver ccd --json");
    AK_CHECK(root != NULL);
    if (root) {
        AK_CHECK(cJSON_IsFalse(cJSON_GetObjectItem(root, "reached")));
        AK_CHECK(cJSON_GetObjectItem(root, "error")->valuedouble > 1.0);
        cJSON_Delete(root);
    }
    AK_CHECK_EQ(run("ik builtin:humanoid --effector left_wrist --target 0.45,1.0,0.25 --solver twobone -o ik.obj", true), 0);
}

AK_TEST(skin_compare_orders_methods) {
    cJSON* root = run_json("skin --compare --json");
    AK_CHECK(root != NULL);
    if (!root) return;
    cJSON* poses = cJSON_GetObjectItem(root, "poses");
    AK_CHECK_EQ(cJSON_GetArraySize(poses), 5); /* bend 90, 120, 150, twist 90, 180 */
    cJSON* bend = cJSON_GetArrayItem(poses, 0);
    cJSON* bend120 = cJSON_GetArrayItem(poses, 1);
    cJSON* twist = cJSON_GetArrayItem(poses, 4);
#define VAL(pose, m, key) cJSON_GetObjectItem(cJSON_GetObjectItem(pose, m), key)->valuedouble
    /* candy wrapper: under a 180-degree twist LBS pinches the blend band (a quarter of the
     * length) towards the axis, so the whole tube loses several percent of its volume and its
     * narrowest section nearly vanishes; DQS and CoR rotate the band rigidly and keep both
     * within the tessellation error (1%). */
    AK_CHECK(VAL(twist, "LBS", "volume_ratio") < 0.95);
    AK_CHECK(VAL(twist, "LBS", "min_radius") < 0.1);
    AK_CHECK(fabs(VAL(twist, "DQS", "volume_ratio") - 1.0) < 0.01);
    AK_CHECK(fabs(VAL(twist, "CoR", "volume_ratio") - 1.0) < 0.01);
    AK_CHECK(VAL(twist, "DQS", "min_radius") > 0.95);
    /* bend: DQS bulges more than CoR */
    AK_CHECK(VAL(bend, "CoR", "max_bulge") < VAL(bend, "DQS", "max_bulge"));
    /* the elbow of LBS and DQS bent 120 degrees interpenetrates; implicit skinning does not
     * collapse under the twist; volume_change is volume_ratio - 1 */
    AK_CHECK(VAL(bend120, "LBS", "self_intersections") > 0 && VAL(bend120, "DQS", "self_intersections") > 0);
    AK_CHECK(VAL(twist, "implicit", "min_radius") > 0.7);
    /* implicit at the 120- and 150-degree bends: no crossing pair, volume within 3% (issue 29) */
    for (int k = 1; k <= 2; ++k) {
        cJSON* b = cJSON_GetArrayItem(poses, k);
        AK_CHECK_EQ(VAL(b, "implicit", "self_intersections"), 0.0);
        AK_CHECK(fabs(VAL(b, "implicit", "volume_change")) < 0.03);
        /* soft at the default desc too: LBS crosses itself there, soft has no crossing pair
         * and keeps the volume within 1% (issue 29) */
        AK_CHECK(VAL(b, "LBS", "self_intersections") > 0);
        AK_CHECK_EQ(VAL(b, "soft", "self_intersections"), 0.0);
        AK_CHECK(fabs(VAL(b, "soft", "volume_change")) < 0.01);
    }
    AK_CHECK_NEAR(VAL(twist, "implicit", "volume_change"), VAL(twist, "implicit", "volume_ratio") - 1.0, 1e-6);
    /* soft (volumetric): the bent tube does not pass through itself where LBS does, and keeps
     * its volume and its section under the twist */
    AK_CHECK(VAL(bend, "LBS", "self_intersections") > 0);
    AK_CHECK_EQ(VAL(bend, "soft", "self_intersections"), 0.0);
    AK_CHECK(fabs(VAL(bend, "soft", "volume_change")) < 0.01);
    AK_CHECK(fabs(VAL(twist, "soft", "volume_change")) < 0.01);
    AK_CHECK(VAL(twist, "soft", "min_radius") > 0.5);
#undef VAL
    cJSON_Delete(root);
}

AK_TEST(weights_json_sum_to_one) {
    AK_CHECK_EQ(run("weights builtin:cylinder --method distance --max-influences 3 -o w.json", true), 0);
    FILE* f = fopen("w.json", "rb");
    AK_CHECK(f != NULL);
    if (!f) return;
    static char buf[1 << 22];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    cJSON* root = cJSON_Parse(buf);
    AK_CHECK(root != NULL);
    if (!root) return;
    int vc = cJSON_GetObjectItem(root, "vertex_count")->valueint;
    AK_CHECK_EQ(cJSON_GetObjectItem(root, "influence_count")->valueint, 3);
    cJSON* w = cJSON_GetObjectItem(root, "weights");
    AK_CHECK_EQ(cJSON_GetArraySize(w), vc * 3);
    double worst = 0.0;
    for (int v = 0; v < vc; ++v) {
        double s = 0;
        for (int k = 0; k < 3; ++k) {
            double x = cJSON_GetArrayItem(w, v * 3 + k)->valuedouble;
            AK_CHECK(x >= 0.0);
            s += x;
        }
        worst = fmax(worst, fabs(s - 1.0));
    }
    AK_CHECK_NEAR(worst, 0.0, 1e-5);
    cJSON_Delete(root);
}

AK_TEST(render_outputs_decode) {
    int w = 0, h = 0, frames = 0;
    AK_CHECK_EQ(run("render builtin:cylinder --clip bend --time 0.5 --size 200x150 -o r.png", true), 0);
    AK_CHECK_EQ(ak_png_info("r.png", &w, &h), AK_OK);
    AK_CHECK(w == 200 && h == 150);
    AK_CHECK_EQ(run("render builtin:cylinder --clip twist --frames 0:1:0.25 --size 120x90 -o r.gif", true), 0);
    AK_CHECK_EQ(ak_gif_info("r.gif", &w, &h, &frames), AK_OK);
    AK_CHECK(w == 120 && h == 90);
    AK_CHECK_EQ(frames, 5);
    AK_CHECK_EQ(run("render builtin:cylinder --fps 10 --duration 0.5 --size 64x48 --method all -o all.gif", true), 0);
    AK_CHECK_EQ(ak_gif_info("all.gif", &w, &h, &frames), AK_OK);
    AK_CHECK_EQ(frames, 5);
    AK_CHECK(w > 3 * 64 && h > 48);
    AK_CHECK_EQ(run("render builtin:humanoid --clip wave --frames 0:0.2:0.1 --size 64x64 --skeleton --weights right_elbow -o seq.png", true), 0);
    for (int i = 0; i < 3; ++i) {
        char path[64];
        snprintf(path, sizeof path, "seq_%04d.png", i);
        AK_CHECK_MSG(ak_png_info(path, &w, &h) == AK_OK && w == 64 && h == 64, "%s", path);
    }
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk -o curves.png", true), 0);
    AK_CHECK_EQ(ak_png_info("curves.png", &w, &h), AK_OK);
    AK_CHECK_EQ(run("weights builtin:cylinder --method heat --bone joint1 -o heat.png", true), 0);
    AK_CHECK_EQ(ak_png_info("heat.png", &w, &h), AK_OK);
    AK_CHECK_EQ(run("ik builtin:humanoid --effector left_wrist --target 0.45,1.0,0.25 -o ik.png", true), 0);
    AK_CHECK_EQ(ak_png_info("ik.png", &w, &h), AK_OK);
}

AK_TEST(demo_writes_its_files) {
    AK_CHECK_EQ(run("demo --size 128x72 -o demo_out", true), 0);
    AK_CHECK(strstr(out_buf, "demo.gif") != NULL);
    AK_CHECK_MSG(strstr(out_buf, "charts") == NULL, "demo printed curves' own line: %s", out_buf);
    int w = 0, h = 0, frames = 0;
    AK_CHECK_EQ(ak_gif_info("demo_out/demo.gif", &w, &h, &frames), AK_OK);
    AK_CHECK(w == 128 && h == 72);
    AK_CHECK(frames > 60);
    const char* stills[] = {"demo_walk.png", "demo_wave.png", "demo_skinning.png", "demo_weights.png", "demo_curves.png",
                            "demo_easing.png"};
    for (size_t i = 0; i < sizeof stills / sizeof stills[0]; ++i) {
        char path[128];
        snprintf(path, sizeof path, "demo_out/%s", stills[i]);
        AK_CHECK_MSG(ak_png_info(path, &w, &h) == AK_OK && w > 0 && h > 0, "%s", path);
    }
}

/* Every glTF: `export --bind` writes each primitive's POSITION accessor, in the loader's
 * documented order (meshes in file order, the nodes instancing each in node order, then
 * primitives; a mesh no node uses once), read here straight from the file. */
AK_TEST(export_bind_reproduces_gltf_positions) {
    char dir[1100];
    if (!ak_test_asset(dir, sizeof dir, "gltf")) {
        AK_SKIP("no assets (set ANIMKIT_ASSETS or put them in ../shared/assets)");
        return;
    }
    const char* files[] = {"RiggedSimple/glTF/RiggedSimple.gltf", "RiggedFigure/glTF-Binary/RiggedFigure.glb",
                           "CesiumMan/glTF-Embedded/CesiumMan.gltf", "Fox/glTF-Binary/Fox.glb",
                           "SimpleSkin/glTF/SimpleSkin.gltf", "SimpleMorph/glTF/SimpleMorph.gltf",
                           "AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb",
                           "MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf",
                           "MorphStressTest/glTF-Binary/MorphStressTest.glb",
                           "RecursiveSkeletons/glTF-Binary/RecursiveSkeletons.glb"};
    static ak_vec3 obj[200000];
    for (size_t f = 0; f < sizeof files / sizeof files[0]; ++f) {
        char path[1300], args[1500];
        snprintf(path, sizeof path, "%s/%s", dir, files[f]);
        snprintf(args, sizeof args, "export '%s' --bind -o bind_asset.obj", path);
        AK_CHECK_MSG(run(args, true) == 0, "%s: %s", files[f], out_buf);
        size_t groups = 0, nv = read_obj_vertices("bind_asset.obj", obj, 200000, &groups);
        doc d;
        if (!doc_open(&d, path)) {
            AK_CHECK_MSG(false, "%s: reference reader", files[f]);
            continue;
        }
        size_t at = 0, expect_groups = 0;
        double worst = 0;
        for (int mi = 0; mi < jsize(d.root, "meshes"); ++mi) {
            const cJSON* prims = jget(jat(d.root, "meshes", mi), "primitives");
            int users = 0;
            for (int ni = 0; ni < jsize(d.root, "nodes"); ++ni) users += jint(jat(d.root, "nodes", ni), "mesh", -1) == mi;
            for (int u = 0; u < (users ? users : 1); ++u) {
                for (int pi = 0; pi < cJSON_GetArraySize(prims); ++pi) {
                    int pa = jint(jget(cJSON_GetArrayItem(prims, pi), "attributes"), "POSITION", -1);
                    int vc = accessor_count(&d, pa);
                    float* pos = vc > 0 ? malloc((size_t)vc * 12) : NULL;
                    ++expect_groups;
                    if (!pos || !doc_floats(&d, pa, 3, pos)) {
                        AK_CHECK_MSG(false, "%s: POSITION accessor %d", files[f], pa);
                        free(pos);
                        continue;
                    }
                    for (int v = 0; v < vc && at < nv; ++v, ++at) {
                        worst = fmax(worst, fabs(obj[at].x - pos[v * 3]));
                        worst = fmax(worst, fabs(obj[at].y - pos[v * 3 + 1]));
                        worst = fmax(worst, fabs(obj[at].z - pos[v * 3 + 2]));
                    }
                    free(pos);
                }
            }
        }
        AK_CHECK_MSG(at == nv, "%s: %zu vertices in the OBJ, %zu in the file", files[f], nv, at);
        AK_CHECK_MSG(groups == expect_groups, "%s: %zu groups, expected %zu", files[f], groups, expect_groups);
        AK_CHECK_MSG(worst == 0.0, "%s: bind positions differ by %.3g", files[f], worst);
        doc_close(&d);
    }
}

/* A scene of more meshes than any fixed-size table would hold (84 skinned instances). */
AK_TEST(render_scene_with_many_meshes) {
    char path[1100];
    if (!ak_test_asset(path, sizeof path, "gltf/RecursiveSkeletons/glTF-Binary/RecursiveSkeletons.glb")) {
        AK_SKIP("RecursiveSkeletons.glb absent (set ANIMKIT_ASSETS)");
        return;
    }
    char args[1300];
    snprintf(args, sizeof args, "render '%s' --time 1 --size 96x64 -o many.png", path);
    AK_CHECK_MSG(run(args, true) == 0, "%s", out_buf);
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info("many.png", &w, &h), AK_OK);
    AK_CHECK(w == 96 && h == 64);
}

/* ---- issue 22: what a new user trips on ------------------------------------------------------ */

#define M_PI_ 3.14159265358979323846

static bool file_exists(const char* path) {
    struct stat st;
    return stat(path, &st) == 0;
}

/* A stick figure (hips, spine, head, two legs; 1.9 units tall) whose root moves +2 in x per
 * frame for frame_count frames, frame_time seconds apart. */
static bool write_walk_bvh(const char* path, int frame_count, double frame_time) {
    FILE* f = fopen(path, "w");
    if (!f) return false;
    fputs("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n"
          "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
          "  JOINT Spine\n  {\n    OFFSET 0 0.5 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
          "    JOINT Head\n    {\n      OFFSET 0 0.5 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n"
          "      End Site\n      {\n        OFFSET 0 0.2 0\n      }\n    }\n  }\n"
          "  JOINT LeftLeg\n  {\n    OFFSET 0.15 -0.45 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
          "    End Site\n    {\n      OFFSET 0 -0.45 0\n    }\n  }\n"
          "  JOINT RightLeg\n  {\n    OFFSET -0.15 -0.45 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
          "    End Site\n    {\n      OFFSET 0 -0.45 0\n    }\n  }\n}\n",
          f);
    fprintf(f, "MOTION\nFrames: %d\nFrame Time: %g\n", frame_count, frame_time);
    for (int i = 0; i < frame_count; ++i) fprintf(f, "%d 0.9 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n", 2 * i);
    return fclose(f) == 0;
}

static bool load_png(const char* path, ak_image* img) {
    memset(img, 0, sizeof *img);
    if (ak_png_info(path, &img->width, &img->height) != AK_OK) return false;
    img->pixels = calloc((size_t)img->width * (size_t)img->height, 4);
    if (img->pixels && ak_png_read(path, img) == AK_OK) return true;
    free(img->pixels);
    img->pixels = NULL;
    return false;
}

typedef struct box2 {
    int x0, y0, x1, y1, count;
} box2;

/* Bounding box of the skeleton overlay's joint discs: the default joint colour (1.0, 0.78, 0.18)
 * is the only saturated orange in a render (background and ground are blue-grey, clay is pale). */
static box2 joint_box(const char* path) {
    box2 b = {1 << 30, 1 << 30, -1, -1, 0};
    ak_image img;
    if (!load_png(path, &img)) return b;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const uint8_t* p = img.pixels + ((size_t)y * (size_t)img.width + (size_t)x) * 4;
            if (!(p[0] > 200 && p[1] > 140 && p[1] < 230 && p[2] < 110)) continue;
            b.x0 = x < b.x0 ? x : b.x0, b.x1 = x > b.x1 ? x : b.x1;
            b.y0 = y < b.y0 ? y : b.y0, b.y1 = y > b.y1 ? y : b.y1;
            ++b.count;
        }
    free(img.pixels);
    return b;
}

/* Pixels warmer than blue (clay: r > b + 8); background, ground and shadows are bluish. */
static box2 warm_box(const char* path) {
    box2 b = {1 << 30, 1 << 30, -1, -1, 0};
    ak_image img;
    if (!load_png(path, &img)) return b;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const uint8_t* p = img.pixels + ((size_t)y * (size_t)img.width + (size_t)x) * 4;
            if (!(p[0] > p[2] + 8)) continue;
            b.x0 = x < b.x0 ? x : b.x0, b.x1 = x > b.x1 ? x : b.x1;
            b.y0 = y < b.y0 ? y : b.y0, b.y1 = y > b.y1 ? y : b.y1;
            ++b.count;
        }
    free(img.pixels);
    return b;
}

/* Item 9: plurals, names as typed, subnormal numbers, the files a multi-frame PNG run writes. */
AK_TEST(messages_say_what_happened) {
    AK_CHECK_EQ(run("export builtin:cylinder -o one.obj", true), 0);
    AK_CHECK_MSG(strstr(out_buf, ": 1 mesh\n") && !strstr(out_buf, "meshes"), "%s", out_buf);
    AK_CHECK_EQ(run("curves builtin:cylinder --clip bend -o one.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, ": 1 chart\n") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("info builtin:cylinder", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "1 channel\n") && !strstr(out_buf, "1 channels"), "%s", out_buf);
    AK_CHECK_EQ(run("export builtin:cylinder --clip nope -o x.obj", true), 1);
    AK_CHECK_MSG(strstr(out_buf, "its clips (by name or number): #0 'bend', #1 'twist', #2 'bend_twist'") != NULL, "%s",
                 out_buf);
    /* an option without its value is named as typed */
    AK_CHECK_EQ(run("render builtin:cylinder -o", true), 2);
    AK_CHECK_MSG(strstr(out_buf, "'-o' needs a value") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("render builtin:cylinder --output", true), 2);
    AK_CHECK_MSG(strstr(out_buf, "'--output' needs a value") != NULL, "%s", out_buf);
    /* repeatable options are bounded */
    char many[2048] = "render builtin:cylinder -o x.png";
    for (int i = 0; i < 70; ++i) strcat(many, " --mesh cylinder");
    AK_CHECK_EQ(run(many, true), 2);
    AK_CHECK_MSG(strstr(out_buf, "too many options") != NULL, "%s", out_buf);
    /* subnormal and underflowing times are numbers (they round to 0 s) */
    AK_CHECK_EQ(run("export builtin:cylinder --time 1e-320 -o sub.obj", true), 0);
    AK_CHECK_EQ(run("export builtin:cylinder --time 1e-400 -o sub.obj", true), 0);
    AK_CHECK_EQ(run("export builtin:cylinder --time 1e400 -o sub.obj", true), 2);
    /* several frames into a PNG: the message names the files written, not OUT.png */
    remove("fr.png");
    AK_CHECK_EQ(run("render builtin:cylinder --clip bend --frames 0:0.5:0.25 --size 64x48 -o fr.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "fr_0000.png") && strstr(out_buf, "fr_0002.png") && strstr(out_buf, "3 frames"), "%s", out_buf);
    AK_CHECK_MSG(!strstr(out_buf, "wrote fr.png"), "%s", out_buf);
    AK_CHECK(file_exists("fr_0002.png") && !file_exists("fr.png"));
}

/* Item 9: MorphStressTest's one weights channel (the loader splits it per primitive) is one
 * channel in info and one chart in curves, as the file declares. */
AK_TEST(info_and_curves_count_file_channels) {
    char path[1100];
    if (!ak_test_asset(path, sizeof path, "gltf/MorphStressTest/glTF-Binary/MorphStressTest.glb")) {
        AK_SKIP("MorphStressTest.glb absent (set ANIMKIT_ASSETS)");
        return;
    }
    doc d;
    AK_CHECK(doc_open(&d, path));
    int file_channels = jsize(jat(d.root, "animations", 0), "channels");
    doc_close(&d);
    char args[1300];
    snprintf(args, sizeof args, "info '%s' --json", path);
    cJSON* root = run_json(args);
    AK_CHECK(root != NULL);
    int info_channels = root ? cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(root, "clips"), 0), "channels")->valueint : -1;
    cJSON_Delete(root);
    snprintf(args, sizeof args, "curves '%s' --clip 0 -o ms.png", path);
    AK_CHECK_EQ(run(args, true), 0);
    const char* colon = strstr(out_buf, "ms.png: ");
    int charts = colon ? atoi(colon + 8) : -1;
    AK_CHECK_EQ(info_channels, file_channels);
    AK_CHECK_MSG(charts == file_channels, "curves drew %d charts, the file has %d channels: %s", charts, file_channels, out_buf);
}

/* Item 9: GIF delays are whole 1/100 s; at 24 fps they must alternate so that 24 frames last
 * exactly one second (all 4 cs would be 25 fps). */
AK_TEST(gif_delays_match_the_rate) {
    int delays[64];
    AK_CHECK_EQ(run("render builtin:cylinder --clip bend --fps 24 --size 48x32 -o d24.gif", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "24 fps") != NULL, "%s", out_buf);
    int n = ref_gif_delays("d24.gif", delays, 64);
    AK_CHECK_EQ(n, 25); /* 0, 1/24, ..., 1 s */
    int sum = 0;
    for (int i = 0; i < 24 && i < n; ++i) {
        AK_CHECK_MSG(delays[i] == 4 || delays[i] == 5, "frame %d delay %d", i, delays[i]);
        sum += delays[i];
    }
    AK_CHECK_EQ(sum, 100);
    AK_CHECK_EQ(run("render builtin:cylinder --clip bend --frames 0:1:0.1 --size 48x32 -o d10.gif", true), 0);
    n = ref_gif_delays("d10.gif", delays, 64);
    AK_CHECK_EQ(n, 11);
    for (int i = 0; i < n; ++i) AK_CHECK_MSG(delays[i] == 10, "frame %d delay %d", i, delays[i]);
}

/* Item 10: a clip longer than 10 s gets 12 fps in a GIF by default, and says so. */
AK_TEST(long_clip_gif_subsampled) {
    AK_CHECK(write_walk_bvh("long_walk.bvh", 13, 1.0)); /* 12 s */
    AK_CHECK_EQ(run("render long_walk.bvh --size 48x32 -o long.gif", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "12 fps") != NULL, "%s", out_buf);
    int delays[256];
    int n = ref_gif_delays("long.gif", delays, 256);
    AK_CHECK_EQ(n, 145); /* 0, 1/12, ..., 12 s */
    int sum = 0;
    for (int i = 0; i < 12 && i < n; ++i) sum += delays[i];
    AK_CHECK_EQ(sum, 100);
    /* --fps alone covers the whole clip at that rate */
    AK_CHECK_EQ(run("render long_walk.bvh --fps 2 --size 48x32 -o long2.gif", true), 0);
    AK_CHECK_EQ(ref_gif_delays("long2.gif", delays, 256), 25);
}

/* Item 5: the size limit holds for the whole image --method all composes. */
AK_TEST(method_all_size_limit) {
    remove("wide.png");
    AK_CHECK_EQ(run("render builtin:cylinder --size 4000x100 --method all -o wide.png", true), 2);
    AK_CHECK_MSG(strstr(out_buf, "8192x8192") != NULL, "%s", out_buf);
    AK_CHECK(!file_exists("wide.png"));
    AK_CHECK_EQ(run("render builtin:cylinder --size 8192x8192 --method all -o huge.png", true), 2);
    AK_CHECK_EQ(run("render builtin:cylinder --size 1600x64 --method all -o wide.png", true), 0);
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info("wide.png", &w, &h), AK_OK);
    AK_CHECK(w > 5 * 1600 && w <= 8192 && h <= 8192); /* five panels: LBS, DQS, CoR, implicit, soft */
}

/* Item 6: nothing to export is an error, not an empty OBJ. */
AK_TEST(export_without_mesh_fails) {
    AK_CHECK(write_walk_bvh("nomesh.bvh", 3, 0.5));
    remove("nomesh.obj");
    AK_CHECK_EQ(run("export nomesh.bvh -o nomesh.obj", true), 1);
    AK_CHECK_MSG(strstr(out_buf, "no mesh to export") && strstr(out_buf, "nomesh.bvh"), "%s", out_buf);
    AK_CHECK(!file_exists("nomesh.obj"));
}

/* Item 4: --camera, --fov, --follow move and scale the picture as a pinhole camera does. */
AK_TEST(render_camera_options) {
    const char* base = "render builtin:humanoid --clip walk --time 0 --size 320x320 --skeleton";
    char a[1400];
    const char* cams[] = {"--camera 0,0,4", "--camera 180,0,4", "--camera 90,0,4", "--camera 0,0,8",
                          "--camera 0,0,8 --fov 20", "--camera 0,80,4"};
    box2 b[6];
    for (int i = 0; i < 6; ++i) {
        char out[32];
        snprintf(out, sizeof out, "cam%d.png", i);
        snprintf(a, sizeof a, "%s %s -o %s", base, cams[i], out);
        AK_CHECK_MSG(run(a, true) == 0, "%s: %s", a, out_buf);
        b[i] = joint_box(out);
        AK_CHECK_MSG(b[i].count > 20, "%s: no joints seen", cams[i]);
    }
    const int W = 320;
    double hgt[6], wid[6];
    for (int i = 0; i < 6; ++i) hgt[i] = b[i].y1 - b[i].y0 - 7.0, wid[i] = b[i].x1 - b[i].x0 - 7.0; /* less the disc */
    /* from behind (yaw 180) the front view mirrors left-right */
    AK_CHECK_MSG(abs(b[0].x0 - (W - 1 - b[1].x1)) <= 6 && abs(b[0].x1 - (W - 1 - b[1].x0)) <= 6, "front %d..%d back %d..%d",
                 b[0].x0, b[0].x1, b[1].x0, b[1].x1);
    AK_CHECK(abs(b[0].y0 - b[1].y0) <= 6 && abs(b[0].y1 - b[1].y1) <= 6);
    /* from the side the shoulders overlap: narrower */
    AK_CHECK_MSG(wid[2] < 0.8 * wid[0], "side width %.0f, front %.0f", wid[2], wid[0]);
    /* twice the distance, half the size (the figure is shallow next to 4 units) */
    AK_CHECK_MSG(fabs(hgt[0] / hgt[3] - 2.0) < 0.2, "height %.0f at 4, %.0f at 8", hgt[0], hgt[3]);
    /* field of view 20 instead of 40 degrees: tan(20)/tan(10) = 2.06 times larger */
    double want = tan(ak_radians(20.0f)) / tan(ak_radians(10.0f));
    AK_CHECK_MSG(fabs(hgt[4] / hgt[3] - want) < 0.12 * want, "fov ratio %.3f, want %.3f", hgt[4] / hgt[3], want);
    /* seen from above, the standing figure is short on screen */
    AK_CHECK_MSG(hgt[5] < 0.5 * hgt[0], "top view height %.0f, front %.0f", hgt[5], hgt[0]);
    AK_CHECK_EQ(run("render builtin:humanoid --camera 10 -o x.png", true), 2);
    AK_CHECK_EQ(run("render builtin:humanoid --camera 10,95 -o x.png", true), 2);
    AK_CHECK_EQ(run("render builtin:humanoid --camera 10,5,-1 -o x.png", true), 2);
    /* empty items are not skipped ("0,,10" used to be yaw 0, pitch 10) */
    AK_CHECK_EQ(run("render builtin:humanoid --camera 0,,10 -o x.png", true), 2);
    AK_CHECK_EQ(run("render builtin:humanoid --camera 0,10, -o x.png", true), 2);
    AK_CHECK_EQ(run("render builtin:humanoid --camera ,0,10 -o x.png", true), 2);
    AK_CHECK_EQ(run("render builtin:humanoid --fov 0 -o x.png", true), 2);
    /* a walk 20 units long: framed on the whole path the figure is small; --follow keeps it
     * large and centred at the start and at the end */
    AK_CHECK(write_walk_bvh("walk20.bvh", 11, 1.0));
    AK_CHECK_EQ(run("render walk20.bvh --frames 0:10:10 --size 200x200 -o still.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "--follow") != NULL, "no hint to use --follow: %s", out_buf);
    AK_CHECK_EQ(run("render walk20.bvh --frames 0:10:10 --size 200x200 --follow -o follow.png", true), 0);
    for (int i = 0; i < 2; ++i) {
        char p1[32], p2[32];
        snprintf(p1, sizeof p1, "still_%04d.png", i);
        snprintf(p2, sizeof p2, "follow_%04d.png", i);
        box2 s = joint_box(p1), f = joint_box(p2);
        AK_CHECK_MSG(s.count > 0 && f.count > 0, "frame %d: joints not seen", i);
        AK_CHECK_MSG(s.y1 - s.y0 < 60, "frame %d: unfollowed figure %d px tall", i, s.y1 - s.y0);
        AK_CHECK_MSG(f.y1 - f.y0 > 100, "frame %d: followed figure only %d px tall", i, f.y1 - f.y0);
        double cx = 0.5 * (f.x0 + f.x1), cy = 0.5 * (f.y0 + f.y1);
        AK_CHECK_MSG(fabs(cx - 100) < 40 && fabs(cy - 100) < 40, "frame %d: followed figure centred at %.0f,%.0f", i, cx, cy);
    }
    char walk[1100];
    if (ak_test_asset(walk, sizeof walk, "bvh/01_01.bvh")) {
        snprintf(a, sizeof a, "render '%s' --frames 0:22.9:22.9 --size 200x200 --follow -o mocap.png", walk);
        AK_CHECK_MSG(run(a, true) == 0, "%s", out_buf);
        for (int i = 0; i < 2; ++i) {
            char p[32];
            snprintf(p, sizeof p, "mocap_%04d.png", i);
            box2 f = joint_box(p);
            double cx = 0.5 * (f.x0 + f.x1), cy = 0.5 * (f.y0 + f.y1);
            AK_CHECK_MSG(f.count > 0 && f.y1 - f.y0 > 90 && fabs(cx - 100) < 45 && fabs(cy - 100) < 45,
                         "01_01 frame %d: %d..%d x %d..%d", i, f.x0, f.x1, f.y0, f.y1);
        }
    }
}

/* Item 7: weights without --bone: every bone's region in its own colour, named. The golden-
 * angle hues include purples (250-350 degrees) that the blue-to-red heatmap never makes. */
AK_TEST(weights_png_shows_every_bone) {
    AK_CHECK_EQ(run("weights builtin:humanoid --method distance -o bones.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "each bone") != NULL, "%s", out_buf);
    ak_image img;
    AK_CHECK(load_png("bones.png", &img));
    if (!img.pixels) return;
    int bins[12] = {0};
    for (size_t i = 0; i < (size_t)img.width * (size_t)img.height; ++i) {
        double r = img.pixels[4 * i] / 255.0, g = img.pixels[4 * i + 1] / 255.0, b = img.pixels[4 * i + 2] / 255.0;
        double mx = fmax(r, fmax(g, b)), mn = fmin(r, fmin(g, b));
        if (mx < 0.3 || (mx - mn) / mx < 0.45) continue;
        double hue = mx == r ? fmod((g - b) / (mx - mn) + 6.0, 6.0) : mx == g ? (b - r) / (mx - mn) + 2.0 : (r - g) / (mx - mn) + 4.0;
        bins[(int)(hue * 60.0 / 30.0) % 12]++;
    }
    free(img.pixels);
    int busy = 0;
    for (int k = 0; k < 12; ++k) busy += bins[k] > 100;
    AK_CHECK_MSG(busy >= 6, "only %d hue bins in use", busy);
    AK_CHECK_MSG(bins[9] + bins[10] + bins[11] > 300, "no purple or magenta region (%d %d %d)", bins[9], bins[10], bins[11]);
    /* --bone still gives that bone's heatmap */
    AK_CHECK_EQ(run("weights builtin:humanoid --method distance --bone left_elbow -o one.png", true), 0);
}

/* CIE 1976 L*a*b* of sRGB bytes (D65), from the standards. */
static void rgb8_to_lab(const uint8_t* px, double out[3]) {
    double rgb[3], xyz[3];
    for (int k = 0; k < 3; ++k) {
        double c = px[k] / 255.0;
        rgb[k] = c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
    }
    xyz[0] = (0.4124 * rgb[0] + 0.3576 * rgb[1] + 0.1805 * rgb[2]) / 0.95047;
    xyz[1] = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    xyz[2] = (0.0193 * rgb[0] + 0.1192 * rgb[1] + 0.9505 * rgb[2]) / 1.08883;
    for (int k = 0; k < 3; ++k) xyz[k] = xyz[k] > 216.0 / 24389.0 ? cbrt(xyz[k]) : (24389.0 / 27.0 * xyz[k] + 16.0) / 116.0;
    out[0] = 116.0 * xyz[1] - 16.0, out[1] = 500.0 * (xyz[0] - xyz[1]), out[2] = 200.0 * (xyz[1] - xyz[2]);
}

/* Issue 33 item 7 (slow: three weight computations; tests/test_view.c checks the palette itself
 * fast): the dominant-bone legend gave spine_02 and right_knee, left_elbow and
 * right_hip the same colour. Now no two legend swatches of builtin:humanoid or CesiumMan are
 * closer than 15 CIE76 units (the swatches are the 9x9 squares at x = 10, y = 40 + 12 row). */
AK_TEST(weights_legend_colours_distinct) {
    char path[1100], args[1300];
    const char* subjects[2] = {"builtin:humanoid", NULL};
    if (ak_test_asset(path, sizeof path, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb")) subjects[1] = path;
    for (int s = 0; s < 2 && subjects[s]; ++s) {
        snprintf(args, sizeof args, "weights %s --method distance -o legend.png", subjects[s]);
        AK_CHECK_EQ(run(args, true), 0);
        ak_image img;
        AK_CHECK(load_png("legend.png", &img));
        if (!img.pixels) return;
        double lab[64][3];
        int rows = 0;
        for (; rows < 48; ++rows) { /* swatches until the background (grey-blue, unsaturated) */
            const uint8_t* px = ak_image_pixel(&img, 14, 44 + 12 * rows);
            int mx = px[0] > px[1] ? (px[0] > px[2] ? px[0] : px[2]) : (px[1] > px[2] ? px[1] : px[2]);
            int mn = px[0] < px[1] ? (px[0] < px[2] ? px[0] : px[2]) : (px[1] < px[2] ? px[1] : px[2]);
            if (mx - mn < 40) break;
            rgb8_to_lab(px, lab[rows]);
        }
        free(img.pixels);
        AK_CHECK_MSG(rows >= 10, "%s: %d legend swatches", subjects[s], rows);
        double worst = 1e9;
        int wi = 0, wj = 0;
        for (int i = 0; i < rows; ++i)
            for (int j = 0; j < i; ++j) {
                double d = sqrt((lab[i][0] - lab[j][0]) * (lab[i][0] - lab[j][0]) + (lab[i][1] - lab[j][1]) * (lab[i][1] - lab[j][1]) +
                                (lab[i][2] - lab[j][2]) * (lab[i][2] - lab[j][2]));
                if (d < worst) worst = d, wi = i, wj = j;
            }
        AK_CHECK_MSG(worst > 15.0, "%s: legend rows %d and %d are %.1f CIE76 units apart", subjects[s], wj, wi, worst);
    }
    if (!subjects[1]) AK_SKIP("CesiumMan.glb absent (set ANIMKIT_ASSETS)");
    remove("legend.png");
}

/* Item 3: curves --channel and --page. */
AK_TEST(curves_select_and_paginate) {
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel 0,2 -o sel.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "2 charts") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel 0-2 -o sel.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "3 charts") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel 2-0 -o sel.png", true), 2);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel 9999 -o sel.png", true), 1);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel nobody -o sel.png", true), 1);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --page 0 -o sel.png", true), 2);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --page 99 -o sel.png", true), 1);
    /* chart sizes: below the plot's 120x80 minimum, or a page above 8192x8192, is bad usage
     * (exit 2) before anything is drawn (8192x8192 charts used to allocate gigabytes) */
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --size 8x8 -o sel.png", true), 2);
    AK_CHECK_MSG(strstr(out_buf, "120..8192") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --size 8192x8192 -o sel.png", true), 2);
    AK_CHECK_MSG(strstr(out_buf, "above the 8192x8192 limit") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel 0 --size 4000x3000 -o sel.png", true), 0);
    int sw = 0, sh = 0;
    AK_CHECK(ak_png_info("sel.png", &sw, &sh) == AK_OK && sw >= 4000 && sw <= 8192 && sh >= 3000 && sh <= 8192);
    char path[1100], a[1300];
    if (!ak_test_asset(path, sizeof path, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb")) {
        AK_SKIP("CesiumMan.glb absent (set ANIMKIT_ASSETS)");
        return;
    }
    /* 57 channels: pages of 24, 24 and 9 */
    int seen = 0;
    for (int page = 1; page <= 3; ++page) {
        snprintf(a, sizeof a, "curves '%s' --clip 0 --page %d -o page.png", path, page);
        AK_CHECK_MSG(run(a, true) == 0, "%s", out_buf);
        const char* c = strstr(out_buf, "page.png: ");
        seen += c ? atoi(c + 10) : 0;
    }
    AK_CHECK_EQ(seen, 57);
    AK_CHECK_MSG(strstr(out_buf, "#48-#56") != NULL, "%s", out_buf);
    snprintf(a, sizeof a, "curves '%s' --clip 0 --page 4 -o page.png", path);
    AK_CHECK_EQ(run(a, true), 1);
    snprintf(a, sizeof a, "curves '%s' --clip 0 --channel Skeleton_torso_joint_1.rotation -o page.png", path);
    AK_CHECK_EQ(run(a, true), 0);
    AK_CHECK_MSG(strstr(out_buf, "1 chart\n") != NULL, "%s", out_buf);
}

/* A UV sphere as an OBJ group with one vertex per triangle corner (unwelded, no normals), as
 * MakeHuman's base.obj stores its body; *base counts the vertices written so far. */
static void obj_sphere(FILE* f, const char* group, double cx, double r, int* base) {
    enum { RINGS = 12, SEGS = 16 };
    fprintf(f, "g %s\n", group);
    for (int i = 0; i < RINGS; ++i)
        for (int j = 0; j < SEGS; ++j) {
            double p[4][3];
            for (int k = 0; k < 4; ++k) {
                int ii = i + (k >= 2), jj = j + (k == 1 || k == 2);
                double th = M_PI_ * ii / RINGS, ph = 2.0 * M_PI_ * jj / SEGS;
                p[k][0] = cx + r * sin(th) * cos(ph), p[k][1] = r * cos(th), p[k][2] = -r * sin(th) * sin(ph);
            }
            const int tri[2][3] = {{0, 2, 1}, {0, 3, 2}};
            for (int t = 0; t < 2; ++t) {
                for (int c = 0; c < 3; ++c) fprintf(f, "v %.6f %.6f %.6f\n", p[tri[t][c]][0], p[tri[t][c]][1], p[tri[t][c]][2]);
                fprintf(f, "f %d %d %d\n", *base + 1, *base + 2, *base + 3);
                *base += 3;
            }
        }
}

/* Item 8: an OBJ character with MakeHuman helpers and a rig file beside it. */
AK_TEST(render_obj_characters) {
    mkdir("mh", 0777);
    FILE* f = fopen("mh/base.obj", "w");
    AK_CHECK(f != NULL);
    if (!f) return;
    int base = 0;
    obj_sphere(f, "body", 0.0, 1.0, &base);
    obj_sphere(f, "helper-tights", 6.0, 0.5, &base);
    obj_sphere(f, "joint-pelvis", -6.0, 0.2, &base);
    fclose(f);
    AK_CHECK(write_file("mh/rig.mhskel", "{\"name\": \"not read\"}\n"));
    AK_CHECK_EQ(run("render mh/base.obj --camera 0,0 --size 200x200 -o obj_body.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "rig.mhskel") && strstr(out_buf, "not read"), "%s", out_buf);
    AK_CHECK_MSG(strstr(out_buf, "2 MakeHuman helper meshes") != NULL, "%s", out_buf);
    box2 body = warm_box("obj_body.png");
    /* the helpers hidden and out of the framing: the body fills the picture */
    AK_CHECK_MSG(body.x1 - body.x0 > 100, "body %d px wide", body.x1 - body.x0);
    AK_CHECK_EQ(run("render mh/base.obj --camera 0,0 --size 200x200 --mesh body --mesh joint-pelvis -o obj_two.png", true), 0);
    box2 two = warm_box("obj_two.png");
    AK_CHECK_MSG(two.count < body.count / 2 && two.x1 - two.x0 > body.x1 - body.x0,
                 "with the far helper the body should shrink: %d px (was %d)", two.count, body.count);
    AK_CHECK_EQ(run("render mh/base.obj --mesh nosuch -o x.png", true), 1);
    AK_CHECK(strstr(out_buf, "nosuch") != NULL);
    AK_CHECK_EQ(run("info mh/base.obj", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "rig.mhskel") != NULL, "info does not say the rig is not read: %s", out_buf);
    /* smooth shading across the unwelded seams: along the middle row of the sphere, neighbouring
     * pixels differ by a little (faceted shading jumps at each of the facet edges) */
    ak_image img;
    AK_CHECK(load_png("obj_body.png", &img));
    if (!img.pixels) return;
    int y = (body.y0 + body.y1) / 2, worst = 0;
    int x0 = body.x0 + (body.x1 - body.x0) / 6, x1 = body.x1 - (body.x1 - body.x0) / 6;
    for (int x = x0; x < x1; ++x) {
        const uint8_t* p = img.pixels + ((size_t)y * (size_t)img.width + (size_t)x) * 4;
        int l0 = p[0] + p[1] + p[2], l1 = p[4] + p[5] + p[6];
        worst = abs(l1 - l0) > worst ? abs(l1 - l0) : worst;
    }
    free(img.pixels);
    AK_CHECK_MSG(worst <= 9, "largest step between neighbouring pixels %d (r+g+b): faceted", worst);
}

/* Issue 33, round two of a new user's stumbles: each message says what happened. */
AK_TEST(messages_round_two) {
    /* an unknown clip lists the clips there are */
    AK_CHECK_EQ(run("render builtin:humanoid --clip nope -o r2.png", true), 1);
    AK_CHECK_MSG(strstr(out_buf, "no clip 'nope'; its clips (by name or number): #0 'walk', #1 'wave'") != NULL, "%s",
                 out_buf);
    /* a time outside the clip is clamped, and the command says so */
    AK_CHECK_EQ(run("export builtin:humanoid --time 99 -o r2.obj", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "note: --time 99 is past the end of clip 'walk' (0 to 1 s): its last pose is used"), "%s",
                 out_buf);
    AK_CHECK_EQ(run("render builtin:humanoid --time -5 -o r2.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "note: --time -5 is before clip 'walk'"), "%s", out_buf);
    AK_CHECK_EQ(run("export builtin:humanoid --time 0.5 -o r2.obj", true), 0);
    AK_CHECK_MSG(!strstr(out_buf, "note:"), "%s", out_buf);
    /* a channel kind alone selects every chart of that kind */
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel rotation -o r2c.png", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "wrote r2c.png") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("curves builtin:humanoid --clip walk --channel rotatoin -o r2c.png", true), 1);
    AK_CHECK_MSG(strstr(out_buf, "'rotatoin' is no joint, chart number or channel kind") != NULL, "%s", out_buf);
    AK_CHECK_EQ(run("terrain --size 17x17 --render -o r2t.obj", true), 2);
    /* export counts as info does: skin joints within the hierarchy's nodes */
    AK_CHECK_EQ(run("export builtin:humanoid -o r2.glb", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "joints in ") && strstr(out_buf, " nodes,"), "%s", out_buf);
}

/* One rule for success output: every file written is announced on stderr, --quiet says nothing
 * (issue 33 item 9); and terrain's --render takes a GIF. Slow: eleven runs with renders. */
AK_TEST(success_output_rule) {
    static const char* const outputs[][2] = {
        {"particles --preset rain --steps 3 --size 32x24 -o r2p.gif", "wrote r2p.gif"},
        {"particles --preset rain --steps 3 --json r2p.json", "wrote r2p.json"},
        {"ik builtin:humanoid --effector left_wrist --target 0.3,1.2,0.1 -o r2i.png", "wrote r2i.png"},
        {"boids --count 20 --steps 2 --json r2b.json", "wrote r2b.json"},
        {"terrain --size 17x17 -o r2t.obj", "wrote r2t.obj"},
    };
    for (size_t i = 0; i < sizeof outputs / sizeof outputs[0]; ++i) {
        for (int quiet = 0; quiet < 2; ++quiet) { /* stderr alone: stdout goes to /dev/null */
            char cmd[1024];
            snprintf(cmd, sizeof cmd, "%s %s%s 2>&1 >/dev/null", AK_CLI_PATH, outputs[i][0], quiet ? " --quiet" : "");
            FILE* p = popen(cmd, "r");
            AK_CHECK(p != NULL);
            if (!p) return;
            size_t n = fread(out_buf, 1, sizeof out_buf - 1, p);
            out_buf[n] = '\0';
            AK_CHECK_EQ(pclose(p), 0);
            if (quiet) AK_CHECK_MSG(n == 0, "%s --quiet: %s", outputs[i][0], out_buf);
            else AK_CHECK_MSG(strstr(out_buf, outputs[i][1]) != NULL, "%s: %s", outputs[i][0], out_buf);
        }
    }
    /* --render with a GIF: the turntable (a GIF always is one) */
    AK_CHECK_MSG(run("terrain --size 17x17 --render -o r2t.gif", true) == 0, "%s", out_buf);
}

int main(void) {
    AK_RUN(usage_and_help);
    AK_RUN(bad_input_paths);
    AK_RUN(info_json_contract);
    AK_RUN(info_json_matches_gltf_files);
    AK_RUN(export_matches_double_precision_skinning);
    AK_RUN(ik_json_contract);
    AK_RUN(skin_compare_orders_methods);
    AK_RUN(weights_json_sum_to_one);
    AK_RUN_SLOW(render_outputs_decode);
    AK_RUN_SLOW(demo_writes_its_files);
    AK_RUN(export_bind_reproduces_gltf_positions);
    AK_RUN(render_scene_with_many_meshes);
    AK_RUN(messages_say_what_happened);
    AK_RUN(info_and_curves_count_file_channels);
    AK_RUN(gif_delays_match_the_rate);
    AK_RUN(long_clip_gif_subsampled);
    AK_RUN(method_all_size_limit);
    AK_RUN(export_without_mesh_fails);
    AK_RUN_SLOW(render_camera_options);
    AK_RUN(weights_png_shows_every_bone);
    AK_RUN_SLOW(weights_legend_colours_distinct);
    AK_RUN_SLOW(curves_select_and_paginate);
    AK_RUN(render_obj_characters);
    AK_RUN_SLOW(messages_round_two); /* ten commands on builtin:humanoid: end to end */
    AK_RUN_SLOW(success_output_rule);
    return ak_test_finish();
}
