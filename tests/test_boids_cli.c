/* animkit boids: exit codes, error messages naming the key, the --json contract checked against
 * values computed here (order parameter, smallest distance in double), thread independence. */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include <sys/wait.h>

#include "ak_test.h"

#ifndef AK_CLI_PATH
#error "AK_CLI_PATH must name the animkit executable"
#endif

static char out_buf[1 << 20];

/* Run "animkit ARGS" with stderr merged into the captured output; return the exit status. */
static int run(const char* args) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s %s 2>&1", AK_CLI_PATH, args);
    FILE* p = popen(cmd, "r");
    if (!p) return -1;
    size_t n = fread(out_buf, 1, sizeof out_buf - 1, p);
    out_buf[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void write_file(const char* path, const char* text) {
    FILE* f = fopen(path, "w");
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

static char* read_file(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

AK_TEST(usage) {
    AK_CHECK_EQ(run("boids --help"), 0);
    AK_CHECK(strstr(out_buf, "usage: animkit boids") != NULL);
    AK_CHECK_EQ(run("help"), 0);
    AK_CHECK(strstr(out_buf, "boids") != NULL);
    AK_CHECK_EQ(run("boids --frobnicate"), 2);
    AK_CHECK_EQ(run("boids --count abc"), 2);
    AK_CHECK_EQ(run("boids --count 0"), 2);
    AK_CHECK_EQ(run("boids --dt 0"), 2);
    AK_CHECK_EQ(run("boids --threads 65"), 2);
    AK_CHECK_EQ(run("boids -o out.txt"), 2);
    AK_CHECK_EQ(run("boids --size 10"), 2);
    AK_CHECK_EQ(run("boids a.json b.json"), 2);
    AK_CHECK_EQ(run("boids no_such_scene.json"), 1);
    AK_CHECK(strstr(out_buf, "no_such_scene.json") != NULL);
    AK_CHECK_EQ(run("boids --count 50 --steps 3"), 0);
    AK_CHECK(strstr(out_buf, "50 agents") != NULL);
}

AK_TEST(bad_scenes_name_the_key) {
    static const struct {
        const char* text;
        const char* expect;
    } cases[] = {
        {"{\"species\": [{\"view_angle\": 400}]}", "species[0].view_angle"},
        {"{\"species\": [{\"k_nearest\": 65}]}", "species[0].k_nearest"},
        {"{\"species\": [{\"min_speed\": 5, \"max_speed\": 1}]}", "species[0].min_speed"},
        {"{\"species\": [{\"flee\": [3]}]}", "species[0].flee[0]"},
        {"{\"species\": [{\"pursue\": [2.2e82]}]}", "species[0].pursue[0]"}, /* fuzz: was a UB cast */
        {"{\"species\": [{\"flee\": [0.5]}]}", "species[0].flee[0]"},
        {"{\"species\": [{\"colour\": [1, 0, 0]}]}", "colour"},
        {"{\"species\": []}", "species"},
        {"{\"obstacles\": [{\"type\": \"cone\"}]}", "obstacles[0].type"},
        {"{\"obstacles\": [{\"type\": \"sphere\", \"radius\": -1}]}", "obstacles[0].radius"},
        {"{\"obstacles\": [{\"type\": \"plane\", \"normal\": [0, 0, 0]}]}", "obstacles[0].normal"},
        {"{\"obstacles\": [{\"type\": \"box\", \"radius\": 1}]}", "radius"},
        {"{\"agents\": [{\"v\": [1, 0, 0]}]}", "agents[0].p"},
        {"{\"agents\": [{\"p\": [0, 0]}]}", "agents[0].p"},
        {"{\"agents\": [{\"p\": [0, 0, 0], \"species\": 1}]}", "agents[0].species"},
        {"{\"bounds\": {\"min\": [0, 0, 0], \"max\": [1, -1, 1]}}", "bounds.max"},
        {"{\"bounds\": {\"mode\": \"bounce\"}}", "bounds.mode"},
        {"{\"leader\": {\"index\": 5}, \"agents\": [{\"p\": [0, 0, 0]}]}", "leader.index"},
        {"{\"dt\": 0}", "dt"},
        {"{\"dtt\": 1}", "dtt"},
        {"{\"steps\": 1.5}", "steps"},
        {"{\"dt\": 0.1,", "line"},
        {"[1, 2]", "not an object"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        write_file("bad_boids.json", cases[i].text);
        const int rc = run("boids bad_boids.json --steps 1");
        AK_CHECK_MSG(rc == 1, "case %zu: exit %d (%s)", i, rc, out_buf);
        AK_CHECK_MSG(strstr(out_buf, "bad_boids.json") && strstr(out_buf, cases[i].expect),
                     "case %zu: message '%s' lacks '%s'", i, out_buf, cases[i].expect);
    }
    /* --count with listed agents is a usage error. */
    write_file("agents_boids.json", "{\"agents\": [{\"p\": [0, 0, 0]}, {\"p\": [1, 0, 0]}]}");
    AK_CHECK_EQ(run("boids agents_boids.json --count 5"), 2);
}

static double len3d(double x, double y, double z) { return sqrt(x * x + y * y + z * z); }

AK_TEST(json_contract) {
    /* Zero steps: the agents come back exactly as given; order and min distance by hand. */
    write_file("three_boids.json",
               "{\"agents\": [{\"p\": [0, 0, 0], \"v\": [1, 0, 0]}, {\"p\": [3, 4, 0], \"v\": [0, 2, 0]},"
               " {\"p\": [0, 0.5, 0], \"v\": [0, 0, 0]}]}");
    AK_CHECK_EQ(run("boids three_boids.json --steps 0 --json three_out.json"), 0);
    cJSON* root = cJSON_Parse(read_file("three_out.json"));
    AK_CHECK(root != NULL);
    if (!root) return;
    AK_CHECK_EQ(cJSON_GetArraySize(root), 4); /* exactly steps, agents, order, min_distance */
    AK_CHECK_EQ(cJSON_GetObjectItem(root, "steps")->valueint, 0);
    cJSON* agents = cJSON_GetObjectItem(root, "agents");
    AK_CHECK_EQ(cJSON_GetArraySize(agents), 3);
    AK_CHECK_NEAR(cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetArrayItem(agents, 1), "p"), 1)->valuedouble, 4.0, 0);
    AK_CHECK_EQ(cJSON_GetArraySize(cJSON_GetArrayItem(agents, 0)), 2); /* p and v only */
    /* order = |(1,0,0) + (0,1,0) + 0| / 3 */
    AK_CHECK_NEAR(cJSON_GetObjectItem(root, "order")->valuedouble, sqrt(2.0) / 3.0, 1e-7);
    AK_CHECK_NEAR(cJSON_GetObjectItem(root, "min_distance")->valuedouble, 0.5, 1e-7);
    cJSON_Delete(root);

    /* A real run: order and min distance recomputed from the written agents. */
    AK_CHECK_EQ(run("boids --count 300 --steps 40 --seed 3 --json run1.json --threads 1"), 0);
    char* t1 = read_file("run1.json");
    root = cJSON_Parse(t1);
    AK_CHECK(root != NULL);
    if (!root) return;
    agents = cJSON_GetObjectItem(root, "agents");
    const int n = cJSON_GetArraySize(agents);
    AK_CHECK_EQ(n, 300);
    double sx = 0, sy = 0, sz = 0, best = 1e300;
    double(*P)[3] = malloc((size_t)n * sizeof *P);
    int i = 0;
    for (cJSON* a = agents->child; a; a = a->next, ++i) {
        cJSON *p = cJSON_GetObjectItem(a, "p"), *v = cJSON_GetObjectItem(a, "v");
        for (int k = 0; k < 3; ++k) P[i][k] = cJSON_GetArrayItem(p, k)->valuedouble;
        const double vx = cJSON_GetArrayItem(v, 0)->valuedouble, vy = cJSON_GetArrayItem(v, 1)->valuedouble,
                     vz = cJSON_GetArrayItem(v, 2)->valuedouble, l = len3d(vx, vy, vz);
        AK_CHECK(l <= 4.0 * (1 + 1e-6)); /* the default max_speed */
        if (l > 0) {
            sx += vx / l;
            sy += vy / l;
            sz += vz / l;
        }
    }
    for (int a = 0; a < n; ++a)
        for (int b = a + 1; b < n; ++b)
            best = fmin(best, len3d(P[a][0] - P[b][0], P[a][1] - P[b][1], P[a][2] - P[b][2]));
    free(P);
    AK_CHECK_NEAR(cJSON_GetObjectItem(root, "order")->valuedouble, len3d(sx, sy, sz) / n, 1e-6);
    AK_CHECK_NEAR(cJSON_GetObjectItem(root, "min_distance")->valuedouble, best, 1e-6 * best);
    AK_CHECK_EQ(cJSON_GetObjectItem(root, "steps")->valueint, 40);
    cJSON_Delete(root);
    /* Two threads: byte-identical output. */
    char* copy = strdup(t1);
    AK_CHECK_EQ(run("boids --count 300 --steps 40 --seed 3 --json run2.json --threads 2"), 0);
    AK_CHECK(strcmp(copy, read_file("run2.json")) == 0);
    AK_CHECK_EQ(run("boids --count 300 --steps 40 --seed 4 --json run3.json"), 0);
    AK_CHECK(strcmp(copy, read_file("run3.json")) != 0); /* the seed matters */
    free(copy);
}

AK_TEST(render_and_example_scene) {
    char args[1024];
    snprintf(args, sizeof args, "boids %s/examples/boids_flock.json --steps 20 --count 100 -o boids.png --size 160x120",
             AK_SOURCE_DIR);
    AK_CHECK_EQ(run(args), 0);
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info("boids.png", &w, &h), AK_OK);
    AK_CHECK_EQ(w, 160);
    AK_CHECK_EQ(h, 120);
    snprintf(args, sizeof args, "boids %s/examples/boids_flock.json --steps 6 --2d -o boids.gif --size 96x64",
             AK_SOURCE_DIR);
    AK_CHECK_EQ(run(args), 0);
    int frames = 0;
    AK_CHECK_EQ(ak_gif_info("boids.gif", &w, &h, &frames), AK_OK);
    AK_CHECK_EQ(frames, 7);
}

int main(void) {
    AK_RUN(usage);
    AK_RUN(bad_scenes_name_the_key);
    AK_RUN(json_contract);
    AK_RUN(render_and_example_scene);
    return ak_test_finish();
}
