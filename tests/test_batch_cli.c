/* animkit batch on the command line: --shard I/N splits a manifest so that every job runs in
 * exactly one shard, a re-run skips what is up to date, a bad job is a row with an error and
 * exit 1 while the others still run, and usage errors exit 2. The slow case retargets every
 * shared BVH file onto builtin:humanoid and CesiumMan in two shards and re-loads each output. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include "ak_test.h"
#include "cli_test.h"

/* Count the rows of out_buf per job index (counts[index]) and per status. */
static void tally(int* counts, size_t max, int* ran, int* skipped, int* failed) {
    for (char* line = out_buf; line && *line;) {
        char* nl = strchr(line, '\n');
        if (nl) *nl = '\0';
        cJSON* o = cJSON_Parse(line);
        AK_CHECK_MSG(o != NULL, "not a JSON row: %s", line);
        if (o) {
            const cJSON* ix = cJSON_GetObjectItemCaseSensitive(o, "index");
            const cJSON* st = cJSON_GetObjectItemCaseSensitive(o, "status");
            if (cJSON_IsNumber(ix) && ix->valueint >= 0 && (size_t)ix->valueint < max) ++counts[ix->valueint];
            if (cJSON_IsString(st)) {
                *ran += strcmp(st->valuestring, "ran") == 0;
                *skipped += strcmp(st->valuestring, "skipped") == 0;
                *failed += strcmp(st->valuestring, "failed") == 0;
            }
            cJSON_Delete(o);
        }
        line = nl ? nl + 1 : NULL;
    }
}

AK_TEST(shards_cover_every_job_once_and_rerun_skips) {
    mkdir("batch_cli", 0777);
    FILE* f = fopen("batch_cli/jobs.jsonl", "w");
    AK_CHECK(f != NULL);
    if (!f) return;
    for (int k = 0; k < 6; ++k) {
        if (k == 2) fputs("\n", f); /* a blank line is no job */
        if (k == 4)
            fputs("{\"kind\": \"render\", \"inputs\": {\"model\": \"builtin:nobody\"}, \"output\": \"bad.png\"}\n", f);
        else
            fprintf(f,
                    "{\"kind\": \"render\", \"inputs\": {\"model\": \"builtin:cylinder\"},"
                    " \"parameters\": {\"time\": %d, \"size\": [32, 24]}, \"output\": \"r%d.png\"}\n",
                    k, k);
    }
    fclose(f);
    for (int k = 0; k < 6; ++k) {
        char p[64];
        snprintf(p, sizeof p, "batch_cli/out/r%d.png", k);
        remove(p);
        snprintf(p, sizeof p, "batch_cli/out/r%d.png" AK_BATCH_RECORD_SUFFIX, k);
        remove(p);
    }
    int counts[8] = {0}, ran = 0, skipped = 0, failed = 0;
    for (int i = 0; i < 3; ++i) {
        char args[256];
        snprintf(args, sizeof args, "batch batch_cli/jobs.jsonl --shard %d/3 --out batch_cli/out", i);
        const int rc = run(args, false);
        /* job 4 (the bad one) is in shard 1 */
        AK_CHECK_MSG(rc == (i == 1 ? 1 : 0), "shard %d: exit %d", i, rc);
        tally(counts, 8, &ran, &skipped, &failed);
    }
    for (int k = 0; k < 6; ++k) AK_CHECK_MSG(counts[k] == 1, "job %d ran in %d shards", k, counts[k]);
    AK_CHECK(counts[6] == 0 && counts[7] == 0);
    AK_CHECK(ran == 5 && failed == 1 && skipped == 0);
    struct stat st;
    AK_CHECK(stat("batch_cli/out/r5.png", &st) == 0 && st.st_size > 0);
    AK_CHECK(stat("batch_cli/out/r5.png" AK_BATCH_RECORD_SUFFIX, &st) == 0);
    AK_CHECK(stat("batch_cli/out/bad.png", &st) != 0);
    /* the whole manifest again: every good job is up to date */
    memset(counts, 0, sizeof counts);
    ran = skipped = failed = 0;
    AK_CHECK_EQ(run("batch batch_cli/jobs.jsonl --out batch_cli/out", false), 1);
    tally(counts, 8, &ran, &skipped, &failed);
    AK_CHECK(ran == 0 && skipped == 5 && failed == 1);
    /* --force runs them */
    ran = skipped = failed = 0;
    AK_CHECK_EQ(run("batch batch_cli/jobs.jsonl --shard 0/3 --out batch_cli/out --force", false), 0);
    tally(counts, 8, &ran, &skipped, &failed);
    AK_CHECK(ran == 2 && skipped == 0 && failed == 0);
    /* the bad job's row names the problem */
    AK_CHECK_EQ(run("batch batch_cli/jobs.jsonl --shard 1/3 --out batch_cli/out", true), 1);
    AK_CHECK(strstr(out_buf, "builtin:nobody") != NULL);
}

AK_TEST(usage_errors) {
    AK_CHECK_EQ(run("batch", false), 2);
    AK_CHECK_EQ(run("batch batch_cli/jobs.jsonl --shard 3/3", false), 2);
    AK_CHECK_EQ(run("batch batch_cli/jobs.jsonl --shard 1", false), 2);
    AK_CHECK_EQ(run("batch batch_cli/jobs.jsonl --shard -1/2", false), 2);
    AK_CHECK_EQ(run("batch batch_cli/jobs.jsonl --shard 0/0", false), 2);
    AK_CHECK_EQ(run("batch batch_cli/no_such.jsonl", false), 1);
    AK_CHECK_EQ(run("batch --help", false), 0);
    AK_CHECK(strstr(out_buf, "--shard I/N") != NULL);
}

/* Every shared BVH onto builtin:humanoid and CesiumMan, in two shards; the outputs re-load with
 * one clip as long as the source's (within a frame). */
AK_TEST(shared_bvh_onto_humanoid_and_cesiumman) {
    char bvh[4][1200], cesium[1200];
    const char* names[4] = {"bvh/01_01.bvh", "bvh/02_01.bvh", "bvh/131_03.bvh", "bvh/49_04.bvh"};
    for (int k = 0; k < 4; ++k)
        if (!ak_test_asset(bvh[k], sizeof bvh[k], names[k])) {
            AK_SKIP("%s absent (set ANIMKIT_ASSETS)", names[k]);
            return;
        }
    if (!ak_test_asset(cesium, sizeof cesium, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb")) {
        AK_SKIP("CesiumMan absent");
        return;
    }
    mkdir("batch_cli", 0777);
    /* CesiumMan's joint names follow no rig convention: a map (as tests/test_retarget_assets.c's),
     * named relative to the manifest's folder */
    AK_CHECK(write_file("batch_cli/cesium.map",
                        "Skeleton_torso_joint_1 = Hips\nleg_joint_L_1 = LeftUpLeg\nleg_joint_L_2 = LeftLeg\n"
                        "leg_joint_L_3 = LeftFoot\nleg_joint_R_1 = RightUpLeg\nleg_joint_R_2 = RightLeg\n"
                        "leg_joint_R_3 = RightFoot\nSkeleton_torso_joint_2 = Spine\ntorso_joint_3 = Spine1\n"
                        "Skeleton_neck_joint_1 = Neck\nSkeleton_neck_joint_2 = Head\n"
                        "Skeleton_arm_joint_L__4_ = LeftArm\nSkeleton_arm_joint_L__3_ = LeftForeArm\n"
                        "Skeleton_arm_joint_L__2_ = LeftHand\nSkeleton_arm_joint_R = RightArm\n"
                        "Skeleton_arm_joint_R__2_ = RightForeArm\nSkeleton_arm_joint_R__3_ = RightHand\n"));
    /* jobs: every BVH onto builtin:humanoid, and onto CesiumMan when it names the map's joints
     * (131_03 uses other names) */
    int source_of[8], job_count = 0;
    bool cesium_of[8];
    FILE* f = fopen("batch_cli/bvh.jsonl", "w");
    AK_CHECK(f != NULL);
    if (!f) return;
    for (int b = 0; b < 4; ++b) {
        ak_scene* src = NULL;
        AK_CHECK_EQ(ak_io_load(bvh[b], NULL, NULL, &src, NULL), AK_OK);
        const bool cmu_names = src && src->skeleton && ak_skeleton_find_joint(src->skeleton, "LeftUpLeg") >= 0;
        ak_scene_destroy(src);
        for (int c = 0; c < (cmu_names ? 2 : 1); ++c) {
            fprintf(f, "{\"kind\": \"retarget\", \"inputs\": {\"source\": \"%s\", \"target\": \"%s\"%s}, \"output\": \"bvh/%d.glb\"}\n",
                    bvh[b], c ? cesium : "builtin:humanoid", c ? ", \"map\": \"cesium.map\"" : "", job_count);
            source_of[job_count] = b;
            cesium_of[job_count] = c == 1;
            ++job_count;
        }
    }
    fclose(f);
    int cesium_jobs = 0;
    for (int k = 0; k < job_count; ++k) cesium_jobs += cesium_of[k];
    AK_CHECK_MSG(cesium_jobs >= 1, "no BVH with CMU joint names");
    int counts[8] = {0}, ran = 0, skipped = 0, failed = 0;
    for (int i = 0; i < 2; ++i) {
        char args[256];
        snprintf(args, sizeof args, "batch batch_cli/bvh.jsonl --shard %d/2 --force", i);
        AK_CHECK_EQ(run(args, false), 0);
        tally(counts, 8, &ran, &skipped, &failed);
    }
    AK_CHECK(ran == job_count && failed == 0);
    for (int k = 0; k < job_count; ++k) {
        AK_CHECK_EQ(counts[k], 1);
        char p[64];
        snprintf(p, sizeof p, "batch_cli/bvh/%d.glb", k);
        ak_scene *out = NULL, *src = NULL;
        AK_CHECK_EQ(ak_io_load(p, NULL, NULL, &out, NULL), AK_OK);
        AK_CHECK_EQ(ak_io_load(bvh[source_of[k]], NULL, NULL, &src, NULL), AK_OK);
        if (out && src && out->clip_count == 1 && src->clip_count >= 1)
            AK_CHECK_NEAR(ak_clip_duration(out->clips[0]), ak_clip_duration(src->clips[0]), 1.0f / 30.0f + 1e-4f);
        else
            AK_CHECK_MSG(false, "%s: no clip", p);
        /* the output carries the target's skeleton */
        if (out) AK_CHECK(ak_scene_joint_count(out) > 0);
        ak_scene_destroy(out);
        ak_scene_destroy(src);
    }
}

int main(void) {
    AK_RUN(shards_cover_every_job_once_and_rerun_skips);
    AK_RUN(usage_errors);
    AK_RUN_SLOW(shared_bvh_onto_humanoid_and_cesiumman);
    return ak_test_finish();
}
