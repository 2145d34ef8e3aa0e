/* animkit boids: exit codes, error messages naming the key, the --json contract checked against
 * values computed here (order parameter, smallest distance in double), thread independence,
 * grid and naive search, and that the default run and every preset flock (issue 27). */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include "ak_test.h"
#include "cli_test.h"

AK_TEST(usage) {
    AK_CHECK_EQ(run("boids --help", true), 0);
    AK_CHECK(strstr(out_buf, "usage: animkit boids") != NULL);
    AK_CHECK_EQ(run("help", true), 0);
    AK_CHECK(strstr(out_buf, "boids") != NULL);
    AK_CHECK_EQ(run("boids --frobnicate", true), 2);
    AK_CHECK_EQ(run("boids --count abc", true), 2);
    AK_CHECK_EQ(run("boids --count 0", true), 2);
    AK_CHECK_EQ(run("boids --dt 0", true), 2);
    AK_CHECK_EQ(run("boids --threads 65", true), 2);
    AK_CHECK_EQ(run("boids -o out.txt", true), 2);
    AK_CHECK_EQ(run("boids --size 10", true), 2);
    AK_CHECK_EQ(run("boids a.json b.json", true), 2);
    AK_CHECK_EQ(run("boids no_such_scene.json", true), 1);
    AK_CHECK(strstr(out_buf, "no_such_scene.json") != NULL);
    AK_CHECK_EQ(run("boids --count 50 --steps 3", true), 0);
    AK_CHECK(strstr(out_buf, "50 agents") != NULL);
    AK_CHECK_EQ(run("boids --preset starlings", true), 2);
    AK_CHECK(strstr(out_buf, "flock, obstacles, predator") != NULL);
    write_file("preset_and_scene.json", "{}");
    AK_CHECK_EQ(run("boids preset_and_scene.json --preset flock", true), 2);
    AK_CHECK_EQ(run("boids --search kdtree", true), 2);
    AK_CHECK(strstr(out_buf, "grid or naive") != NULL);
    /* The naive search is quadratic: its distance tests are budgeted before the run starts. */
    AK_CHECK_EQ(run("boids --search naive --count 1000000 --steps 1", true), 1);
    AK_CHECK(strstr(out_buf, "--search grid") != NULL);
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
        const int rc = run("boids bad_boids.json --steps 1", true);
        AK_CHECK_MSG(rc == 1, "case %zu: exit %d (%s)", i, rc, out_buf);
        AK_CHECK_MSG(strstr(out_buf, "bad_boids.json") && strstr(out_buf, cases[i].expect),
                     "case %zu: message '%s' lacks '%s'", i, out_buf, cases[i].expect);
    }
    /* --count with listed agents is a usage error. */
    write_file("agents_boids.json", "{\"agents\": [{\"p\": [0, 0, 0]}, {\"p\": [1, 0, 0]}]}");
    AK_CHECK_EQ(run("boids agents_boids.json --count 5", true), 2);
}

static double len3d(double x, double y, double z) { return sqrt(x * x + y * y + z * z); }

AK_TEST(json_contract) {
    /* Zero steps: the agents come back exactly as given; order and min distance by hand. */
    write_file("three_boids.json",
               "{\"agents\": [{\"p\": [0, 0, 0], \"v\": [1, 0, 0]}, {\"p\": [3, 4, 0], \"v\": [0, 2, 0]},"
               " {\"p\": [0, 0.5, 0], \"v\": [0, 0, 0]}]}");
    AK_CHECK_EQ(run("boids three_boids.json --steps 0 --json three_out.json", true), 0);
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
    AK_CHECK_EQ(run("boids --count 300 --steps 40 --seed 3 --json run1.json --threads 1", true), 0);
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
    AK_CHECK_EQ(run("boids --count 300 --steps 40 --seed 3 --json run2.json --threads 2", true), 0);
    AK_CHECK(strcmp(copy, read_file("run2.json")) == 0);
    AK_CHECK_EQ(run("boids --count 300 --steps 40 --seed 4 --json run3.json", true), 0);
    AK_CHECK(strcmp(copy, read_file("run3.json")) != 0); /* the seed matters */
    free(copy);
}

/* Largest |coordinate| per axis of the agents in a --json file (-1 when unreadable). */
static void json_extent(const char* path, double ext[3]) {
    ext[0] = ext[1] = ext[2] = -1.0;
    cJSON* root = cJSON_Parse(read_file(path));
    if (!root) return;
    const cJSON* agents = cJSON_GetObjectItem(root, "agents");
    for (int i = 0; i < cJSON_GetArraySize(agents); ++i) {
        const cJSON* p = cJSON_GetObjectItem(cJSON_GetArrayItem(agents, i), "p");
        for (int a = 0; a < 3; ++a) ext[a] = fmax(ext[a], fabs(cJSON_GetArrayItem(p, a)->valuedouble));
    }
    cJSON_Delete(root);
}

AK_TEST(default_box_grows_with_count) {
    double e[3];
    /* Up to 500 agents: the documented 20 m box. */
    AK_CHECK_EQ(run("boids --count 500 --steps 0 --json box500.json", true), 0);
    json_extent("box500.json", e);
    for (int a = 0; a < 3; ++a) AK_CHECK(e[a] > 9.0 && e[a] <= 10.0);
    /* 4,000 agents in 3D: 8x the agents, 2x the side (the same density). */
    AK_CHECK_EQ(run("boids --count 4000 --steps 0 --json box4000.json", true), 0);
    json_extent("box4000.json", e);
    for (int a = 0; a < 3; ++a) AK_CHECK(e[a] > 19.0 && e[a] <= 20.0);
    /* 2,000 agents in 2D: 4x the agents, 2x the side of the plane. */
    AK_CHECK_EQ(run("boids --count 2000 --2d --steps 0 --json box2d.json", true), 0);
    json_extent("box2d.json", e);
    AK_CHECK(e[0] > 19.0 && e[0] <= 20.0 && e[2] > 19.0 && e[2] <= 20.0);
    AK_CHECK_EQ(e[1], 0.0);
    /* Bounds from the scene are kept. */
    write_file("box_given.json", "{\"bounds\": {\"min\": [-5, -5, -5], \"max\": [5, 5, 5]}}");
    AK_CHECK_EQ(run("boids box_given.json --count 4000 --steps 0 --json box_given_out.json", true), 0);
    json_extent("box_given_out.json", e);
    for (int a = 0; a < 3; ++a) AK_CHECK(e[a] > 4.5 && e[a] <= 5.0);
}

AK_TEST(render_and_example_scene) {
    char args[1024];
    snprintf(args, sizeof args, "boids %s/examples/boids_flock.json --steps 20 --count 100 -o boids.png --size 160x120",
             AK_SOURCE_DIR);
    AK_CHECK_EQ(run(args, true), 0);
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info("boids.png", &w, &h), AK_OK);
    AK_CHECK_EQ(w, 160);
    AK_CHECK_EQ(h, 120);
    snprintf(args, sizeof args, "boids %s/examples/boids_flock.json --steps 6 --2d -o boids.gif --size 96x64",
             AK_SOURCE_DIR);
    AK_CHECK_EQ(run(args, true), 0);
    int frames = 0;
    AK_CHECK_EQ(ak_gif_info("boids.gif", &w, &h, &frames), AK_OK);
    AK_CHECK_EQ(frames, 7);
}

/* The grid and the naive search give the same bits; so do the presets on either. */
AK_TEST(search_grid_and_naive) {
    static const char* const runs[] = {"--count 300 --steps 60 --seed 5", "--preset obstacles --count 200 --steps 60",
                                       "--preset predator --count 300 --steps 60"};
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; ++i) {
        char args[256];
        snprintf(args, sizeof args, "boids %s --search grid --json search_grid.json", runs[i]);
        AK_CHECK_EQ(run(args, true), 0);
        char* grid = strdup(read_file("search_grid.json"));
        snprintf(args, sizeof args, "boids %s --search naive --threads 2 --json search_naive.json", runs[i]);
        AK_CHECK_EQ(run(args, true), 0);
        AK_CHECK_MSG(strcmp(grid, read_file("search_naive.json")) == 0, "%s: grid and naive differ", runs[i]);
        free(grid);
    }
}

typedef struct flock_measure {
    int agents, steps;
    double order;     /* as written by the command */
    double cosine;    /* mean cos(v_i, v_j) over the pairs closer than the radius */
    double speed;     /* mean |v| */
    double neighbors; /* pairs closer than the radius per agent, both ways */
} flock_measure;

/* The measures of docs/boids.md ("Defaults and presets") from a --json file, in double: every
 * pair of agents closer than r counts once; an agent at rest counts as cosine 0. */
static bool flock_measure_json(const char* path, double r, flock_measure* m) {
    memset(m, 0, sizeof *m);
    cJSON* root = cJSON_Parse(read_file(path));
    if (!root) return false;
    const cJSON* agents = cJSON_GetObjectItem(root, "agents");
    const int n = cJSON_GetArraySize(agents);
    double(*P)[3] = malloc((size_t)(n > 0 ? n : 1) * sizeof *P);
    double(*V)[3] = malloc((size_t)(n > 0 ? n : 1) * sizeof *V);
    double* S = malloc((size_t)(n > 0 ? n : 1) * sizeof *S);
    int i = 0;
    for (const cJSON* a = agents ? agents->child : NULL; a && i < n; a = a->next, ++i) {
        for (int k = 0; k < 3; ++k) {
            P[i][k] = cJSON_GetArrayItem(cJSON_GetObjectItem(a, "p"), k)->valuedouble;
            V[i][k] = cJSON_GetArrayItem(cJSON_GetObjectItem(a, "v"), k)->valuedouble;
        }
        S[i] = len3d(V[i][0], V[i][1], V[i][2]);
        m->speed += S[i] / n;
    }
    double sum = 0.0;
    long pairs = 0;
    for (int a = 0; a < n; ++a)
        for (int b = a + 1; b < n; ++b) {
            if (!(len3d(P[a][0] - P[b][0], P[a][1] - P[b][1], P[a][2] - P[b][2]) < r)) continue;
            ++pairs;
            if (S[a] > 0 && S[b] > 0)
                sum += (V[a][0] * V[b][0] + V[a][1] * V[b][1] + V[a][2] * V[b][2]) / (S[a] * S[b]);
        }
    m->agents = n;
    m->steps = cJSON_GetObjectItem(root, "steps")->valueint;
    m->order = cJSON_GetObjectItem(root, "order")->valuedouble;
    m->cosine = pairs ? sum / (double)pairs : 0.0;
    m->neighbors = n ? 2.0 * (double)pairs / n : 0.0;
    free(P);
    free(V);
    free(S);
    cJSON_Delete(root);
    return true;
}

/* Issue 27: the default run and every preset form aligned flocks that keep flying. After the
 * default 2000 steps, neighbours within 2.5 m fly aligned (mean cosine >= 0.8) at >= 1 m/s, as
 * docs/boids.md's table says. The old defaults (min_speed 0) fail the same check: the flock
 * stalls in a clump. */
AK_TEST(default_and_presets_flock) {
    /* The flock preset is the default run. */
    AK_CHECK_EQ(run("boids --steps 50 --json flock_default.json", true), 0);
    char* def = strdup(read_file("flock_default.json"));
    AK_CHECK_EQ(run("boids --preset flock --steps 50 --json flock_preset.json", true), 0);
    AK_CHECK(strcmp(def, read_file("flock_preset.json")) == 0);
    free(def);
    static const char* const runs[] = {"", "--preset obstacles", "--preset predator"};
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; ++i) {
        char args[256];
        snprintf(args, sizeof args, "boids %s --json flock_measure.json", runs[i]);
        AK_CHECK_EQ(run(args, true), 0);
        flock_measure m;
        AK_CHECK(flock_measure_json("flock_measure.json", 2.5, &m));
        printf("  boids %-18s order %.3f, neighbour cosine %.3f, speed %.3f m/s, %.1f neighbours\n", runs[i], m.order,
               m.cosine, m.speed, m.neighbors);
        AK_CHECK_EQ(m.steps, 2000); /* the default run */
        AK_CHECK_EQ(m.agents, 500);
        AK_CHECK_MSG(m.cosine >= 0.8, "%s: neighbours fly apart (mean cosine %.3f)", runs[i], m.cosine);
        AK_CHECK_MSG(m.speed >= 1.0, "%s: the flock stalls (mean speed %.3f m/s)", runs[i], m.speed);
        AK_CHECK(m.neighbors >= 4.0); /* flocks, not scattered birds */
        AK_CHECK(m.order > 0.3);      /* the order parameter the table gives is well above noise */
    }
    /* The defaults before issue 27: velocities matched without a speed floor slow to a stall. */
    write_file("old_defaults.json",
               "{\"bounds\": {\"margin\": 2}, \"species\": [{\"min_speed\": 0, \"max_force\": 8,"
               " \"separation_weight\": 1.5, \"separation_radius\": 1, \"alignment_weight\": 1,"
               " \"bounds_weight\": 4}]}");
    AK_CHECK_EQ(run("boids old_defaults.json --json flock_measure.json", true), 0);
    flock_measure m;
    AK_CHECK(flock_measure_json("flock_measure.json", 2.5, &m));
    AK_CHECK_MSG(m.speed < 1.0 && m.order < 0.3, "old defaults: speed %.3f, order %.3f", m.speed, m.order);
}

/* Slow (AK_RUN_SLOW: ctest test_boids_cli_slow, label `slow`): docs/boids.md's table over seeds 1 to 16.
 * Every preset at every seed flies aligned (neighbour cosine >= 0.8) at >= 1 m/s after the
 * default 2000 steps. */
AK_TEST(presets_flock_at_every_seed) {
    static const char* const presets[] = {"flock", "obstacles", "predator"};
    for (size_t i = 0; i < sizeof presets / sizeof presets[0]; ++i) {
        double cos_sum = 0, cos_min = 2, order_sum = 0, order_min = 2, order_max = -1, speed_min = 1e30;
        const int seeds = 16;
        for (int seed = 1; seed <= seeds; ++seed) {
            char args[256];
            snprintf(args, sizeof args, "boids --preset %s --seed %d --json slow_flock_measure.json", presets[i], seed);
            AK_CHECK_EQ(run(args, true), 0);
            flock_measure m;
            AK_CHECK(flock_measure_json("slow_flock_measure.json", 2.5, &m));
            AK_CHECK_MSG(m.cosine >= 0.8 && m.speed >= 1.0, "%s seed %d: neighbour cosine %.3f, speed %.3f m/s",
                         presets[i], seed, m.cosine, m.speed);
            cos_sum += m.cosine;
            cos_min = fmin(cos_min, m.cosine);
            order_sum += m.order;
            order_min = fmin(order_min, m.order);
            order_max = fmax(order_max, m.order);
            speed_min = fmin(speed_min, m.speed);
        }
        printf("  %-9s order %.3f (%.3f, %.3f), neighbour cosine %.3f (%.3f), speed >= %.2f m/s\n", presets[i],
               order_sum / seeds, order_min, order_max, cos_sum / seeds, cos_min, speed_min);
    }
}

int main(void) {
    AK_RUN(usage);
    AK_RUN(bad_scenes_name_the_key);
    AK_RUN(json_contract);
    AK_RUN(default_box_grows_with_count);
    AK_RUN(render_and_example_scene);
    AK_RUN(search_grid_and_naive);
    AK_RUN_SLOW(default_and_presets_flock); /* 4-6 s of flocking runs: end to end */
    AK_RUN_SLOW(presets_flock_at_every_seed);
    return ak_test_finish();
}
