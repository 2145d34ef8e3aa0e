/* animkit boids: run a flock from a scene file (or defaults), write JSON and/or render it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "boids_run.h"
#include "outfile.h"

static const char* const usage =
    "usage: animkit boids [SCENE.json | --preset flock|obstacles|predator] [--count N] [--steps S] [--dt DT]\n"
    "                     [--seed K] [--threads T] [--search grid|naive] [--2d] [--json OUT.json]\n"
    "                     [-o OUT.gif|OUT.png] [--size WxH]\n"
    "Reynolds flocking (separation, alignment, cohesion with a view cone and a k-nearest cap),\n"
    "obstacles, bounds, goal, leader, predators and wander; see docs/boids.md for the scene keys.\n"
    "Without a scene or preset it runs the flock preset (the scene file's defaults).\n"
    "  --preset   flock (500 birds that form aligned flocks), obstacles (the flock around a sphere\n"
    "             and four pillars), predator (3 predators chase the flock, which flees)\n"
    "  --count    agents placed at random in the bounds when the scene has no \"agents\" (default 500;\n"
    "             beyond 500 the default 20 m box grows with the count, so the density stays)\n"
    "  --steps    steps to run (default 2000)       --dt  seconds per step (default 0.02)\n"
    "  --seed     random placement and wander (default 1)\n"
    "  --threads  threads per step (default 1; results are identical for any count)\n"
    "  --search   neighbour search: grid (default) or naive (the O(N^2) reference loop; the same\n"
    "             results, bit for bit)\n"
    "  --2d       agents on the horizontal plane y = 0 (same as \"planar\": true)\n"
    "  --json     write {\"steps\", \"agents\": [{\"p\", \"v\"}], \"order\", \"min_distance\"} after the run\n"
    "  -o         render the flock: .png (last step) or .gif (the run), --size WxH (default 640x480)\n"
    "Without --json or -o prints a summary line.\n";

/* ---- rendering ---------------------------------------------------------------------------- */

typedef struct renderer {
    int w, h;
    ak_raster* raster;
    ak_raster_camera cam;
    ak_vec3 center;
    float extent;
    float ground_y;
    boids_shapes sh;
    uint8_t* pixels;
} renderer;

static int renderer_init(renderer* r, int w, int h, const ak_boids_scene* sc, size_t n) {
    memset(r, 0, sizeof *r);
    r->w = w;
    r->h = h;
    ak_raster_desc d = {.width = w, .height = h, .supersample = 2, .thread_count = 2};
    if (ak_raster_create(&d, NULL, &r->raster) != AK_OK) return 1;
    const ak_boids_params* prm = &sc->params;
    const ak_vec3 lo = prm->bounds_min, hi = prm->bounds_max;
    r->center = ak_vec3_scale(ak_vec3_add(lo, hi), 0.5f);
    r->extent = 0.5f * ak_vec3_length(ak_vec3_sub(hi, lo));
    if (prm->planar) r->center.y = 0.0f;
    r->ground_y = prm->planar ? -0.5f * sc->shape_size - 0.3f : lo.y - 0.05f * r->extent;
    for (uint32_t k = 0; k < prm->obstacle_count; ++k)
        if (boids_is_floor(&prm->obstacles[k])) r->ground_y = prm->obstacles[k].center.y;
    const ak_vec3 eye = ak_vec3_add(r->center, ak_vec3_make(0.9f * r->extent, (prm->planar ? 1.6f : 0.9f) * r->extent,
                                                             1.5f * r->extent));
    r->cam = ak_raster_camera_perspective(eye, r->center, ak_radians(45), (float)w / (float)h, 0.05f * r->extent,
                                          10.0f * r->extent);
    r->pixels = malloc((size_t)w * (size_t)h * 4);
    if (!r->pixels) return 1;
    return boids_shapes_init(&r->sh, sc, n, r->extent) ? 0 : 1;
}

static void renderer_free(renderer* r) {
    ak_raster_destroy(r->raster);
    boids_shapes_free(&r->sh);
    free(r->pixels);
}

/* One frame: every agent a small bird (a body and two wings that flap) or fish (a body whose
 * tail sways), aligned with its velocity, animated by the beat clip at the agent's own phase. */
static ak_result draw_frame(renderer* r, const ak_boids_scene* sc, const boids_run* st, float time, ak_image* out) {
    ak_raster_mesh birds, obs;
    boids_shapes_update(&r->sh, sc, st, time, &birds, &obs);
    ak_raster_mesh casters[2] = {birds, obs};
    ak_raster_clear(r->raster, ak_vec4_make(0.80f, 0.86f, 0.93f, 1), ak_vec4_make(0.55f, 0.60f, 0.68f, 1));
    ak_raster_ground g = {.height = r->ground_y, .center = r->center, .half_extent = 1.6f * r->extent,
                          .casters = casters, .caster_count = r->sh.otri ? 2 : 1};
    ak_result res = ak_raster_draw_ground(r->raster, &r->cam, &g);
    if (res == AK_OK && r->sh.otri) res = ak_raster_draw_mesh(r->raster, &r->cam, &obs);
    if (res == AK_OK) res = ak_raster_draw_mesh(r->raster, &r->cam, &birds);
    if (res == AK_OK) res = ak_raster_resolve(r->raster, out);
    return res;
}

/* ---- the command -------------------------------------------------------------------------- */

static int write_json(const char* path, long steps, const boids_run* st) {
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "boids", path)) return CLI_BAD_INPUT;
    FILE* f = out.f;
    const float order = ak_boids_order((ak_vec3_cspan){st->velocities, st->agent_count});
    float dmin = 0.0f;
    if (st->agent_count >= 2) {
        const size_t bytes = ak_boids_min_distance_scratch_size(st->agent_count);
        uint8_t* scr = malloc(bytes);
        if (!scr || ak_boids_min_distance((ak_vec3_cspan){st->positions, st->agent_count}, (ak_u8_span){scr, bytes}, &dmin) != AK_OK)
            dmin = 0.0f;
        free(scr);
    }
    fprintf(f, "{\"steps\": %ld, \"agents\": [", steps);
    for (size_t i = 0; i < st->agent_count; ++i)
        fprintf(f, "%s{\"p\": [%.9g, %.9g, %.9g], \"v\": [%.9g, %.9g, %.9g]}", i ? ", " : "", (double)st->positions[i].x,
                (double)st->positions[i].y, (double)st->positions[i].z, (double)st->velocities[i].x, (double)st->velocities[i].y, (double)st->velocities[i].z);
    fprintf(f, "], \"order\": %.9g, \"min_distance\": %.9g}\n", (double)order, (double)dmin);
    return cli_outfile_commit(&out, "boids");
}

int cmd_boids(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--count", NULL, true},   {"--steps", NULL, true}, {"--dt", NULL, true},   {"--seed", NULL, true},
        {"--threads", NULL, true}, {"--2d", NULL, false},   {"--json", NULL, true}, {"--output", "-o", true},
        {"--size", NULL, true},    {"--preset", NULL, true}, {"--search", NULL, true},
    };
    cli_args a;
    int rc = cli_parse("boids", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count > 1) return cli_usage("boids", "expected at most one SCENE.json");
    const char* preset = CLI_GET(&a, "--preset");
    if (preset && a.pos_count == 1) return cli_usage("boids", "give a scene file or --preset, not both");
    const char* search = CLI_GET(&a, "--search");
    if (search && strcmp(search, "grid") != 0 && strcmp(search, "naive") != 0)
        return cli_usage("boids", "--search '%s' must be grid or naive", search);
    const bool naive = search && strcmp(search, "naive") == 0;
    long count = -1, steps = -1, seed = -1, threads = 1;
    float dt = -1.0f;
    int w = 640, h = 480;
    if (CLI_GET(&a, "--count") && !cli_parse_int(CLI_GET(&a, "--count"), 1, AK_BOIDS_SCENE_MAX_AGENTS, &count))
        return cli_usage("boids", "--count '%s' is not a whole number in [1, %u]", CLI_GET(&a, "--count"),
                         AK_BOIDS_SCENE_MAX_AGENTS);
    if (CLI_GET(&a, "--steps") && !cli_parse_int(CLI_GET(&a, "--steps"), 0, 100000000, &steps))
        return cli_usage("boids", "--steps '%s' is not a whole number >= 0", CLI_GET(&a, "--steps"));
    if (CLI_GET(&a, "--seed") && !cli_parse_int(CLI_GET(&a, "--seed"), 0, 2147483647, &seed))
        return cli_usage("boids", "--seed '%s' is not a whole number >= 0", CLI_GET(&a, "--seed"));
    if (CLI_GET(&a, "--threads") && !cli_parse_int(CLI_GET(&a, "--threads"), 1, 64, &threads))
        return cli_usage("boids", "--threads '%s' is not a whole number in [1, 64]", CLI_GET(&a, "--threads"));
    if (CLI_GET(&a, "--dt") && (!cli_parse_float(CLI_GET(&a, "--dt"), &dt) || !(dt >= 1e-6f) || dt > 10.0f))
        return cli_usage("boids", "--dt '%s' is not a number in [1e-06, 10] (seconds)", CLI_GET(&a, "--dt"));
    if (CLI_GET(&a, "--size") && (!cli_parse_size(CLI_GET(&a, "--size"), &w, &h) || w > 4096 || h > 4096))
        return cli_usage("boids", "--size '%s' is not WxH (at most 4096x4096)", CLI_GET(&a, "--size"));
    const char* out = CLI_GET(&a, "--output");
    const char* json = CLI_GET(&a, "--json");
    if (out && !cli_has_ext(out, ".png") && !cli_has_ext(out, ".gif"))
        return cli_usage("boids", "output '%s' must end in .png or .gif", out);

    ak_boids_scene sc;
    ak_diag diag;
    ak_boids_scene_defaults(&sc);
    if (preset) {
        const ak_result res = ak_boids_scene_preset(preset, &sc, &diag);
        if (res == AK_ERR_NOT_FOUND)
            return cli_usage("boids", "--preset '%s' must be one of " AK_BOIDS_SCENE_PRESETS, preset);
        if (res != AK_OK) return cli_fail("boids", "out of memory");
    }
    if (a.pos_count == 1 && ak_boids_scene_load_file(a.pos[0], &sc, &diag) != AK_OK) {
        ak_boids_scene_free(&sc);
        return cli_fail("boids", "%s", diag.message);
    }
    if (count > 0) {
        if (sc.agent_count > 0) {
            ak_boids_scene_free(&sc);
            return cli_usage("boids", "--count conflicts with the scene's \"agents\"");
        }
        sc.count = (size_t)count;
    }
    if (steps >= 0) sc.steps = steps;
    if (seed >= 0) sc.seed = seed;
    if (dt > 0.0f) sc.dt = dt;
    if (CLI_GET(&a, "--2d")) sc.params.planar = true;
    if (sc.agent_count == 0) ak_boids_scene_scale_bounds(&sc, sc.count);

    boids_run st;
    memset(&st, 0, sizeof st);
    const double agents = (double)(sc.agent_count > 0 ? sc.agent_count : sc.count);
    if ((rc = cli_work_check("boids", agents * (double)sc.steps, "agent updates (agents x steps)",
                             "--steps or --count")) ||
        (naive && (rc = cli_work_check("boids", agents * agents * (double)sc.steps,
                                       "distance tests of the naive search (agents^2 x steps)",
                                       "--steps or --count, or use --search grid"))) ||
        (rc = boids_run_init(&st, &sc, "boids", a.pos_count ? a.pos[0] : preset ? preset : "scene", (uint32_t)threads,
                             naive))) {
        boids_run_free(&st);
        ak_boids_scene_free(&sc);
        return rc;
    }
    ak_result res = AK_OK;

    renderer rd;
    ak_gif_writer* gif = NULL;
    ak_image img = {0};
    bool rendering = out != NULL;
    const bool is_gif = out && cli_has_ext(out, ".gif");
    if (rendering) {
        if (renderer_init(&rd, w, h, &sc, st.n)) {
            renderer_free(&rd);
            boids_run_free(&st);
            ak_boids_scene_free(&sc);
            return cli_fail("boids", "out of memory for rendering");
        }
        img = (ak_image){.pixels = rd.pixels, .width = w, .height = h};
        if (is_gif && ak_gif_writer_create(out, &(ak_gif_desc){.width = w, .height = h, .delay_cs = 4}, NULL, &gif) != AK_OK) {
            renderer_free(&rd);
            boids_run_free(&st);
            ak_boids_scene_free(&sc);
            return cli_fail("boids", "%s: cannot create the file", out);
        }
    }
    const long every = sc.steps > 150 ? (sc.steps + 149) / 150 : 1;
    const double t0 = cli_now();
    long failed_step = -1;
    ak_result wres = AK_OK; /* writing -o: its failures name the file */
    for (long s = 0; s <= sc.steps && res == AK_OK && wres == AK_OK; ++s) {
        if (gif && s % every == 0) {
            res = draw_frame(&rd, &sc, &st, (float)s * sc.dt, &img);
            if (res == AK_OK) wres = ak_gif_writer_add_frame(gif, &img);
        }
        if (s == sc.steps) break;
        if (res == AK_OK && (res = boids_run_step(&st, s)) != AK_OK) failed_step = s;
        cli_progress("boids", (size_t)s + 1, (size_t)sc.steps);
    }
    const double elapsed = cli_now() - t0;
    if (res == AK_OK && rendering && !is_gif) {
        res = draw_frame(&rd, &sc, &st, (float)sc.steps * sc.dt, &img);
        if (res == AK_OK) wres = ak_png_write(out, &img);
    }
    if (gif && (res != AK_OK || wres != AK_OK)) ak_gif_writer_discard(gif); /* no partial GIF */
    else if (gif) wres = ak_gif_writer_finish(gif);
    if (rendering) renderer_free(&rd);
    rc = CLI_OK;
    if (res != AK_OK && failed_step >= 0) rc = cli_fail("boids", "step %ld: %s", failed_step, boids_run_error(res));
    else if (res != AK_OK) rc = cli_fail("boids", "%s", ak_result_string(res));
    else if (wres != AK_OK) rc = cli_fail("boids", "%s: cannot write the file: %s", out, ak_result_string(wres));
    if (rc == CLI_OK && out) cli_wrote(out, "%zu agents after %ld steps", st.n, sc.steps);
    if (rc == CLI_OK && json && (rc = write_json(json, sc.steps, &st)) == CLI_OK)
        cli_wrote(json, "%zu agents after %ld steps", st.n, sc.steps);
    if (rc == CLI_OK && !json && !out) {
        float dmin = 0.0f;
        const size_t bytes = ak_boids_min_distance_scratch_size(st.n);
        uint8_t* scr = st.n >= 2 ? malloc(bytes) : NULL;
        if (scr) ak_boids_min_distance((ak_vec3_cspan){st.p, st.n}, (ak_u8_span){scr, bytes}, &dmin);
        free(scr);
        printf("boids: %zu agents, %ld steps in %.3f s (%.3f ms/step), order %.4f, min distance %.4g\n", st.n,
               sc.steps, elapsed, sc.steps ? 1e3 * elapsed / (double)sc.steps : 0.0,
               (double)ak_boids_order((ak_vec3_cspan){st.v, st.n}), (double)dmin);
    }
    boids_run_free(&st);
    ak_boids_scene_free(&sc);
    return rc;
}
