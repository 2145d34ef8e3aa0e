/* animkit crowd: exit codes, error messages naming the key, the --json contract (exact keys,
 * values checked against what this test computes from the output: time = steps x dt, the
 * smallest clearance at least the run's min_distance, collisions of a scene that starts
 * overlapping), thread independence, every preset run to the end with all agents home
 * (issue 30; slow case). */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include "ak_test.h"
#include "gltf_validate.h"
#include "cli_test.h"

AK_TEST(usage) {
    AK_CHECK_EQ(run("crowd --help", true), 0);
    AK_CHECK(strstr(out_buf, "usage: animkit crowd") != NULL);
    AK_CHECK_EQ(run("help", true), 0);
    AK_CHECK(strstr(out_buf, "crowd") != NULL);
    AK_CHECK_EQ(run("crowd --frobnicate", true), 2);
    AK_CHECK_EQ(run("crowd --agents 0", true), 2);
    AK_CHECK_EQ(run("crowd --agents abc", true), 2);
    AK_CHECK_EQ(run("crowd --steps -1", true), 2);
    AK_CHECK_EQ(run("crowd --dt 0", true), 2);
    AK_CHECK_EQ(run("crowd --dt nan", true), 2);
    AK_CHECK_EQ(run("crowd --threads 65", true), 2);
    AK_CHECK_EQ(run("crowd -o out.txt", true), 2);
    AK_CHECK_EQ(run("crowd --method rvo", true), 2);
    AK_CHECK(strstr(out_buf, "orca or vision") != NULL);
    AK_CHECK_EQ(run("crowd --vision-view gl", true), 2);
    AK_CHECK(strstr(out_buf, "raycast or raster") != NULL);
    AK_CHECK_EQ(run("crowd --preset stadium", true), 2);
    AK_CHECK(strstr(out_buf, "circle, crossing, corridor, evacuation") != NULL);
    AK_CHECK_EQ(run("crowd a.json b.json", true), 2);
    write_file("crowd_two.json", "{\"agents\": [{\"position\": [-3, 0], \"goal\": [3, 0]},"
                                 " {\"position\": [3, 0], \"goal\": [-3, 0]}]}");
    AK_CHECK_EQ(run("crowd crowd_two.json --preset circle", true), 2);
    AK_CHECK_EQ(run("crowd crowd_two.json --agents 5", true), 2);
    AK_CHECK_EQ(run("crowd no_such_crowd.json", true), 1);
    AK_CHECK(strstr(out_buf, "no_such_crowd.json") != NULL);
    /* more characters than the glTF bake holds (nodes, memory budget): a clear error before
     * any step, no file */
    remove("crowd_never.glb");
    AK_CHECK_EQ(run("crowd --agents 60000 --steps 1 -o crowd_never.glb", true), 1);
    AK_CHECK(read_file("crowd_never.glb") == NULL);
    AK_CHECK(strstr(out_buf, "budget") != NULL && strstr(out_buf, "60000 agents") != NULL);
    /* the work budget, before any work */
    AK_CHECK_EQ(run("crowd --agents 1000000 --steps 100000", true), 1);
    AK_CHECK(strstr(out_buf, "budget") != NULL);
    AK_CHECK_EQ(run("crowd crowd_two.json --steps 3", true), 0);
    AK_CHECK(strstr(out_buf, "2 agents") != NULL);
}

AK_TEST(bad_scenes_name_the_key) {
    static const struct {
        const char* text;
        const char* expect;
    } cases[] = {
        {"{\"agents\": [{\"goal\": [1, 0]}]}", "agents[0].position"},
        {"{\"agents\": [{\"position\": [0, 0]}]}", "agents[0]"},
        {"{\"agents\": [{\"position\": [0, 0], \"goal\": [1, 0], \"path\": [[1, 0]]}]}", "agents[0]"},
        {"{\"agents\": [{\"position\": [0, 0, 0], \"goal\": [1, 0]}]}", "agents[0].position"},
        {"{\"agents\": [{\"position\": [0, 1e9], \"goal\": [1, 0]}]}", "agents[0].position"},
        {"{\"agents\": [{\"position\": [0, 0], \"path\": []}]}", "agents[0].path"},
        {"{\"agents\": [{\"position\": [0, 0], \"path\": [[1, 0], [2]]}]}", "agents[0].path[1]"},
        {"{\"agents\": [{\"position\": [0, 0], \"goal\": [1, 0], \"radius\": -1}]}", "agents[0].radius"},
        {"{\"agents\": [{\"position\": [0, 0], \"goal\": [1, 0], \"max_neighbors\": 65}]}", "agents[0].max_neighbors"},
        {"{\"agents\": [{\"position\": [0, 0], \"goal\": [1, 0], \"pref_speed\": 3, \"max_speed\": 2}]}",
         "agents[0].max_speed"},
        {"{\"agents\": [{\"position\": [0, 0], \"goal\": [1, 0], \"speed\": 1}]}", "speed"},
        {"{\"agent_defaults\": {\"time_horizon\": 0}}", "agent_defaults.time_horizon"},
        {"{\"obstacles\": [{\"vertices\": [[0, 0]]}]}", "obstacles[0].vertices"},
        {"{\"obstacles\": [{\"vertices\": [[0, 0], [0, 1], [1, 1], [1, 0]]}]}", "counter-clockwise"},
        {"{\"obstacles\": [{\"points\": []}]}", "points"},
        {"{\"obstacles\": [{\"vertices\": [[0, 0], [1, 0], [1, 0]]}]}", "obstacles[0].vertices[2]"},
        {"{\"agents\": [{\"position\": [0, 0], \"goal\": [1, 0], \"pref_speed\": 0}]}", "agents[0].pref_speed"},
        {"{\"method\": \"rvo\"}", "method"},
        {"{\"vision_view\": \"gl\"}", "vision_view"},
        {"{\"contact_iterations\": 65}", "contact_iterations"},
        {"{\"dt\": 0}", "dt"},
        {"{\"steps\": 1.5}", "steps"},
        {"{}", "no agents"},
        {"{\"dt\": 0.1,", "line"},
        {"[1, 2]", "not an object"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        write_file("bad_crowd.json", cases[i].text);
        const int rc = run("crowd bad_crowd.json --steps 1", true);
        AK_CHECK_MSG(rc == 1, "case %zu: exit %d (%s)", i, rc, out_buf);
        AK_CHECK_MSG(strstr(out_buf, "bad_crowd.json") && strstr(out_buf, cases[i].expect),
                     "case %zu: message '%s' lacks '%s'", i, out_buf, cases[i].expect);
    }
}

/* The --json keys exactly, and the values this test can compute from them. Returns the
 * parsed file (the caller deletes it) or NULL after failing. */
static cJSON* check_contract(const char* path, size_t agents, double time) {
    cJSON* j = read_json(path);
    AK_CHECK(j != NULL);
    if (!j) return NULL;
    const char* keys[] = {"time", "agents", "min_distance", "collisions"};
    int k = 0;
    for (const cJSON* e = j->child; e; e = e->next, ++k)
        AK_CHECK_MSG(k < 4 && strcmp(e->string, keys[k]) == 0, "key %d is '%s'", k, e->string);
    AK_CHECK_EQ(k, 4);
    AK_CHECK_NEAR(cJSON_GetObjectItem(j, "time")->valuedouble, time, 1e-4 * time + 1e-6);
    const cJSON* ag = cJSON_GetObjectItem(j, "agents");
    AK_CHECK_EQ(cJSON_GetArraySize(ag), (int)agents);
    double px[64], pz[64];
    int i = 0;
    for (const cJSON* a = ag->child; a; a = a->next, ++i) {
        const cJSON* p = cJSON_GetObjectItem(a, "position");
        const cJSON* v = cJSON_GetObjectItem(a, "velocity");
        const cJSON* g = cJSON_GetObjectItem(a, "goal_reached");
        AK_CHECK(cJSON_GetArraySize(a) == 3 && p && v && g && cJSON_IsBool(g));
        AK_CHECK(cJSON_GetArraySize(p) == 2 && cJSON_GetArraySize(v) == 2);
        if (i < 64 && p) {
            px[i] = cJSON_GetArrayItem(p, 0)->valuedouble;
            pz[i] = cJSON_GetArrayItem(p, 1)->valuedouble;
        }
    }
    /* the run's minimum is at most the final positions' clearance (radius 0.3 each) */
    double final_min = INFINITY;
    for (int a = 0; a < i && a < 64; ++a)
        for (int b = a + 1; b < i && b < 64; ++b) final_min = fmin(final_min, hypot(px[a] - px[b], pz[a] - pz[b]) - 0.6);
    const cJSON* md = cJSON_GetObjectItem(j, "min_distance");
    AK_CHECK(cJSON_IsNumber(md) && md->valuedouble <= final_min + 1e-5);
    const cJSON* col = cJSON_GetObjectItem(j, "collisions");
    AK_CHECK(cJSON_IsNumber(col) && col->valuedouble >= 0 && col->valuedouble == floor(col->valuedouble));
    return j;
}

static bool all_home(const cJSON* j) {
    for (const cJSON* a = cJSON_GetObjectItem(j, "agents")->child; a; a = a->next)
        if (!cJSON_IsTrue(cJSON_GetObjectItem(a, "goal_reached"))) return false;
    return true;
}

AK_TEST(json_contract_head_on) {
    AK_CHECK_EQ(run("crowd crowd_two.json --steps 120 --dt 0.1 --json crowd_two_out.json", true), 0);
    cJSON* j = check_contract("crowd_two_out.json", 2, 12.0);
    if (!j) return;
    AK_CHECK(all_home(j));
    AK_CHECK(cJSON_GetObjectItem(j, "min_distance")->valuedouble >= -1e-3);
    AK_CHECK_EQ(cJSON_GetObjectItem(j, "collisions")->valueint, 0);
    cJSON_Delete(j);
}

/* Two agents placed 0.4 m apart (radii 0.3: 0.2 m overlap), no contact passes: the start
 * counts, so min_distance is -0.2 and the pair is one collision. */
/* --method vision: the same contract; two agents head-on pass without touching. */
AK_TEST(vision_head_on) {
    AK_CHECK_EQ(run("crowd crowd_two.json --method vision --steps 120 --json crowd_two_vision.json", true), 0);
    cJSON* j = check_contract("crowd_two_vision.json", 2, 12.0);
    if (!j) return;
    AK_CHECK(all_home(j));
    AK_CHECK(cJSON_GetObjectItem(j, "min_distance")->valuedouble >= -1e-3);
    AK_CHECK_EQ(cJSON_GetObjectItem(j, "collisions")->valueint, 0);
    cJSON_Delete(j);
    /* and "method" in the scene file */
    write_file("crowd_two_v.json", "{\"method\": \"vision\", \"agents\": [{\"position\": [-3, 0], \"goal\": [3, 0]},"
                                   " {\"position\": [3, 0], \"goal\": [-3, 0]}]}");
    AK_CHECK_EQ(run("crowd crowd_two_v.json --steps 120 --json crowd_two_v_out.json", true), 0);
    char* a = strdup(read_file("crowd_two_vision.json"));
    AK_CHECK(a && strcmp(a, read_file("crowd_two_v_out.json")) == 0);
    free(a);
    /* the raster view (--vision-view, and "vision_view" in the file: the same run) */
    AK_CHECK_EQ(run("crowd crowd_two.json --method vision --vision-view raster --steps 120 --json crowd_two_r.json", true),
                0);
    j = check_contract("crowd_two_r.json", 2, 12.0);
    if (!j) return;
    AK_CHECK(all_home(j));
    AK_CHECK(cJSON_GetObjectItem(j, "min_distance")->valuedouble >= -1e-3);
    AK_CHECK_EQ(cJSON_GetObjectItem(j, "collisions")->valueint, 0);
    cJSON_Delete(j);
    write_file("crowd_two_rv.json", "{\"method\": \"vision\", \"vision_view\": \"raster\", \"agents\": [{\"position\":"
                                    " [-3, 0], \"goal\": [3, 0]}, {\"position\": [3, 0], \"goal\": [-3, 0]}]}");
    AK_CHECK_EQ(run("crowd crowd_two_rv.json --steps 120 --json crowd_two_rv_out.json", true), 0);
    a = strdup(read_file("crowd_two_r.json"));
    AK_CHECK(a && strcmp(a, read_file("crowd_two_rv_out.json")) == 0);
    free(a);
}

AK_TEST(collisions_counted) {
    write_file("crowd_overlap.json", "{\"contact_iterations\": 0, \"agents\": [{\"position\": [0, 0], \"goal\": [0, 5]},"
                                     " {\"position\": [0.4, 0], \"goal\": [0.4, 5]}, {\"position\": [9, 0], \"goal\": [9, 5]}]}");
    AK_CHECK_EQ(run("crowd crowd_overlap.json --steps 5 --json crowd_overlap_out.json", true), 0);
    cJSON* j = check_contract("crowd_overlap_out.json", 3, 0.5);
    if (!j) return;
    AK_CHECK_NEAR(cJSON_GetObjectItem(j, "min_distance")->valuedouble, -0.2, 1e-5);
    AK_CHECK_EQ(cJSON_GetObjectItem(j, "collisions")->valueint, 1);
    cJSON_Delete(j);
}

AK_TEST(presets_and_threads) {
    static const char* const presets[] = {"circle", "crossing", "corridor", "evacuation"};
    for (int p = 0; p < 4; ++p) {
        char cmd[256], a1[64], a2[64];
        snprintf(a1, sizeof a1, "crowd_%s_1.json", presets[p]);
        snprintf(a2, sizeof a2, "crowd_%s_2.json", presets[p]);
        snprintf(cmd, sizeof cmd, "crowd --preset %s --agents 12 --json %s", presets[p], a1);
        AK_CHECK_EQ(run(cmd, true), 0);
        cJSON* j = read_json(a1);
        AK_CHECK(j != NULL);
        if (!j) continue;
        const double t = cJSON_GetObjectItem(j, "time")->valuedouble;
        cJSON_Delete(j);
        j = check_contract(a1, 12, t);
        if (!j) continue;
        AK_CHECK_MSG(all_home(j), "preset %s: not every agent at its goal after its default steps", presets[p]);
        cJSON_Delete(j);
        /* the same bytes on 2 threads */
        snprintf(cmd, sizeof cmd, "crowd --preset %s --agents 12 --threads 2 --json %s", presets[p], a2);
        AK_CHECK_EQ(run(cmd, true), 0);
        char* t1 = strdup(read_file(a1));
        AK_CHECK(t1 && strcmp(t1, read_file(a2)) == 0);
        free(t1);
    }
}

/* Untrusted input: 5000 agents stacked on one point make every pass quadratic; the run stops
 * with the budget error before that work, and no partial GIF is left. */
AK_TEST(stacked_agents_budget) {
    FILE* f = fopen("crowd_stacked.json", "w");
    AK_CHECK(f != NULL);
    if (!f) return;
    fputs("{\"agents\": [", f);
    for (int i = 0; i < 5000; ++i) fprintf(f, "%s{\"position\": [1, 2], \"goal\": [3, 4]}", i ? ", " : "");
    fputs("]}", f);
    fclose(f);
    remove("crowd_stacked.gif");
    AK_CHECK_EQ(run("crowd crowd_stacked.json --steps 2 -o crowd_stacked.gif", true), 1);
    AK_CHECK(strstr(out_buf, "budget") != NULL);
    AK_CHECK(read_file("crowd_stacked.gif") == NULL);
}

/* The fast share of the preset test: 200 steps of the crossing on 1 and 2 threads, same bytes. */
AK_TEST(threads_same_bytes) {
    AK_CHECK_EQ(run("crowd --preset crossing --agents 12 --steps 200 --json crowd_t1.json", true), 0);
    AK_CHECK_EQ(run("crowd --preset crossing --agents 12 --steps 200 --threads 2 --json crowd_t2.json", true), 0);
    char* t1 = strdup(read_file("crowd_t1.json"));
    AK_CHECK(t1 && strcmp(t1, read_file("crowd_t2.json")) == 0);
    free(t1);
    cJSON* j = check_contract("crowd_t1.json", 12, 20.0);
    cJSON_Delete(j);
}

AK_TEST(render) {
    remove("crowd_out.png");
    AK_CHECK_EQ(run("crowd --preset evacuation --agents 9 --steps 20 -o crowd_out.png --size 64x48", true), 0);
    const char* png = read_file("crowd_out.png");
    AK_CHECK(png && memcmp(png, "\x89PNG", 4) == 0);
}

/* Characters above 500 agents: 600 agents draw with shared poses (the default above 500) and
 * with --poses exact (each agent posed, planted and skinned: the per-agent reference); the two
 * images agree but for the phase quantisation and the planted feet (under 2% of the pixels
 * differ by more than 64 levels in a channel), and the people cover as many pixels (within
 * 10%): prisms (the old drawing above 500 agents) or missing agents would not. */
static bool read_png(const char* path, ak_image* img) {
    int w = 0, h = 0;
    if (ak_png_info(path, &w, &h) != AK_OK) return false;
    *img = (ak_image){.pixels = malloc((size_t)w * (size_t)h * 4), .width = w, .height = h};
    return img->pixels && ak_png_read(path, img) == AK_OK;
}

AK_TEST(render_characters_above_500) {
    remove("crowd_600_shared.png");
    remove("crowd_600_exact.png");
    AK_CHECK_EQ(run("crowd --preset crossing --agents 600 --steps 8 -o crowd_600_shared.png --size 320x240", true), 0);
    AK_CHECK(strstr(out_buf, "(characters)") != NULL);
    AK_CHECK_EQ(run("crowd --preset crossing --agents 600 --steps 8 -o crowd_600_exact.png --size 320x240 --poses exact",
                    true),
                0);
    AK_CHECK_EQ(run("crowd --poses some", true), 2);
    ak_image a, b;
    AK_CHECK(read_png("crowd_600_shared.png", &a));
    AK_CHECK(read_png("crowd_600_exact.png", &b));
    if (!a.pixels || !b.pixels || a.width != b.width || a.height != b.height) {
        free(a.pixels);
        free(b.pixels);
        return;
    }
    size_t differ, people_a, people_b;
    const size_t n = (size_t)a.width * (size_t)a.height;
    crowd_people_pixels(&a, &b, &people_a, &people_b, &differ);
    printf("  600 agents, 320x240: people %zu px shared, %zu px exact; %zu px differ by > 64\n", people_a, people_b,
           differ);
    AK_CHECK(people_b > n / 100); /* the reference shows the crowd at all */
    AK_CHECK(fabs((double)people_a - (double)people_b) < 0.1 * (double)people_b);
    AK_CHECK(differ < n / 50);
    free(a.pixels);
    free(b.pixels);
}

/* -o X.glb: a skinned character per agent. Read back: one node per agent plus the character's
 * 17 joints each, one skin and one mesh per agent, an animation lasting steps x dt whose agent
 * root translations at the end are the positions the --json of the same run reports, and
 * facing: the root turns the humanoid's +z onto the last velocity's direction (within the
 * heading's smoothing). */
AK_TEST(gltf_export) {
    remove("crowd_chars.glb");
    AK_CHECK_EQ(run("crowd --preset crossing --agents 8 --steps 40 --json crowd_chars.json -o crowd_chars.glb", true), 0);
    cJSON* j = read_json("crowd_chars.json");
    ak_scene* sc = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load("crowd_chars.glb", NULL, NULL, &sc, &diag), AK_OK);
    if (!sc || !j) {
        cJSON_Delete(j);
        ak_scene_destroy(sc);
        return;
    }
    AK_CHECK_EQ(sc->skin_count, 8u);
    AK_CHECK_EQ(sc->mesh_count, 8u);
    AK_CHECK_EQ(sc->clip_count, 1u);
    const size_t n = ak_scene_joint_count(sc);
    AK_CHECK(n >= 8 * 18);
    AK_CHECK_NEAR(ak_clip_duration(sc->clips[0]), 4.0f, 1e-5f);
    ak_transform* local = malloc(n * sizeof *local);
    ak_scene_rest_pose(sc, (ak_transform_span){local, n});
    ak_clip_sample(sc->clips[0], 4.0f, NULL, (ak_transform_span){local, n}, (ak_f32_span){0}, (ak_f32_span){0});
    int i = 0;
    for (const cJSON* a = cJSON_GetObjectItem(j, "agents")->child; a; a = a->next, ++i) {
        char name[32];
        snprintf(name, sizeof name, "crowd_%d", i);
        const int node = ak_skeleton_find_joint(sc->skeleton, name);
        AK_CHECK(node >= 0);
        if (node < 0) continue;
        const cJSON* p = cJSON_GetObjectItem(a, "position");
        const cJSON* v = cJSON_GetObjectItem(a, "velocity");
        AK_CHECK_NEAR(local[node].translation.x, cJSON_GetArrayItem(p, 0)->valuedouble, 1e-4);
        AK_CHECK_NEAR(local[node].translation.y, 0.0, 1e-6);
        AK_CHECK_NEAR(local[node].translation.z, cJSON_GetArrayItem(p, 1)->valuedouble, 1e-4);
        const ak_vec3 f = ak_quat_rotate(local[node].rotation, ak_vec3_make(0, 0, 1));
        const double vx = cJSON_GetArrayItem(v, 0)->valuedouble, vz = cJSON_GetArrayItem(v, 1)->valuedouble;
        const double sp = sqrt(vx * vx + vz * vz);
        if (sp > 0.5) AK_CHECK_MSG((f.x * vx + f.z * vz) / sp > 0.95, "agent %d faces %g, %g, walks %g, %g", i,
                                   (double)f.x, (double)f.z, vx, vz);
    }
    AK_CHECK_EQ(i, 8);
    free(local);
    ak_scene_destroy(sc);
    cJSON_Delete(j);
}

/* The Khronos validator on a crowd's glTF (slow: node starts in about a second), and on one
 * of 10,000 agents, the most the presets promise (190,000 joint nodes, more than the
 * int16 skeletons of before held; one mesh placed 10,000 times with a skin each; an 84 MB
 * file the validator reads in about 130 s of CPU and 1.4 GB). */
AK_TEST(gltf_export_validator) {
    remove("crowd_chars_v.glb");
    remove("crowd_chars_10000.glb");
    AK_CHECK_EQ(run("crowd --preset circle --agents 6 --steps 30 -o crowd_chars_v.glb", true), 0);
    AK_CHECK_EQ(run("crowd --preset crossing --agents 10000 --steps 4 -o crowd_chars_10000.glb", true), 0);
    ak_scene* sc = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load("crowd_chars_10000.glb", NULL, NULL, &sc, &diag), AK_OK);
    if (sc) {
        AK_CHECK_EQ(sc->skin_count, 10000u);
        AK_CHECK_EQ(sc->mesh_count, 10000u);
        AK_CHECK(ak_scene_joint_count(sc) >= 10000u * 19u);
    }
    ak_scene_destroy(sc);
    const char* names[] = {"crowd_chars_v.glb", "crowd_chars_10000.glb"};
    ak_test_gltf_validate(names, 2, "crowd file");
}

int main(void) {
    AK_RUN(usage);
    AK_RUN(bad_scenes_name_the_key);
    AK_RUN(json_contract_head_on);
    AK_RUN(vision_head_on);
    AK_RUN(collisions_counted);
    AK_RUN(threads_same_bytes);
    AK_RUN_SLOW(presets_and_threads);
    AK_RUN(stacked_agents_budget);
    AK_RUN(render);
    AK_RUN(render_characters_above_500);
    AK_RUN(gltf_export);
    AK_RUN_SLOW(gltf_export_validator);
    return ak_test_finish();
}
