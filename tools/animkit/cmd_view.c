/* animkit view: a window on a model (SDL2), or the same loop headless for scripts and CI. */
#include <stdlib.h>
#include <string.h>

#include "view_app.h"
#include "outfile.h"

#define MAX_SCRIPT_SIZE (4u << 20)

static const char* const usage =
    "usage: animkit view FILE|builtin:NAME|SIM [--clip C] [--size WxH] [--script FILE] [--headless]\n"
    "                    [--ik-log FILE] [--frames N] [--supersample N] [--threads N] [--stats]\n"
    "                    [--shot-dir DIR] [--seed K]\n"
    "       animkit view crowd|rigid [--preset P | SCENE.json] [options above]\n"
    "Open a window on the model, shaded by animkit's own rasterizer, playing clip C (default the\n"
    "first). The camera starts framed on the first pose as `animkit render` frames one time.\n"
    "SIM runs a simulation live: particles:SCENE.json, particles:preset:fountain|rain|fireworks|\n"
    "character, boids[:SCENE.json], boids:preset:flock|obstacles|predator, cloth:SCENE.json,\n"
    "cloth:preset:flag|curtain|drape|cape (space pauses, right steps one frame, r restarts, left\n"
    "drag on a sphere collider moves it, a/d/q/e change the wind of particles and cloth), or shows\n"
    "terrain[:preset:hills|mountains|dunes] (g new seed, t next fractal, e erodes, r the first\n"
    "terrain), or crowd [--preset circle|crossing|corridor|evacuation | SCENE.json] (also\n"
    "crowd:preset:P, crowd:SCENE.json; a left click on the ground sends the nearest group there,\n"
    "g: the whole crowd), or rigid [--preset stack|pyramid|dominoes|avalanche|ragdoll|incline |\n"
    "SCENE.json] (also rigid:preset:P, rigid:SCENE.json; default the ragdoll preset; a right\n"
    "click throws a sphere from the camera); docs/view.md.\n"
    "  --size WxH       window size (default 960x600)\n"
    "  --script FILE    replay input from FILE, one event a line: key NAME, mouse_down BUTTON X Y,\n"
    "                   mouse_move X Y, mouse_up BUTTON X Y, wheel DY, wait FRAMES,\n"
    "                   screenshot PATH, quit ('#' comments); time then steps 1/30 s per frame and\n"
    "                   the viewer exits at the end of the script. A bad script exits 2 naming the\n"
    "                   line. BUTTON: left, middle, right; X Y in window pixels.\n"
    "  --headless       the same loop with no window (no display needed)\n"
    "  --frames N       headless without a script: run N frames (default 1)\n"
    "  --ik-log FILE    after each IK solve, one JSON line: {\"frame\": n, \"solver\": s,\n"
    "                   \"effector\": name, \"target\": [x,y,z], \"reached\": b, \"error\": e}\n"
    "  --supersample N  anti-aliasing samples per axis, 1..4 (default 1 for speed; render uses 2)\n"
    "  --threads N      raster threads, 1..64 (default 2); given, also the simulation's threads\n"
    "                   (default 1; the results are the same for any count)\n"
    "  --seed K         simulation seed, 0..18446744073709551615 (default: particles 1, boids the\n"
    "                   scene's seed (K modulo 2^31), terrain 0; the cloth has no randomness)\n"
    "  --stats          print the frame-time breakdown at exit (stderr)\n"
    "  --shot-dir DIR   where the P key writes view_NNNN.png and a script's screenshot PATH goes\n"
    "                   (default .); PATH stays inside it: no absolute path, no '..', no symlink\n"
    "keys:\n";

static void print_usage(void) {
    fputs(usage, stdout);
    for (size_t i = 0; i < view_help_count; ++i) printf("  %-8s %s\n", view_help[i].key, view_help[i].what);
    printf("mouse: left drag orbits (on a joint: picks the IK effector and drags its target; on the\n"
           "bottom bar: scrubs); middle or shift+left drag pans; the wheel zooms.\n");
    const view_sim* sim;
    for (size_t k = 0; (sim = view_sim_at(k)) != NULL; ++k) {
        const view_help_entry* list[64];
        size_t n = view_help_list(sim, list, 64);
        printf("keys with %s:\n", sim->name);
        for (size_t i = 0; i < n; ++i) printf("  %-8s %s\n", list[i]->key, list[i]->what);
    }
    printf("This build %s a window (SDL2).\n", view_window_available() ? "has" : "does not have");
}

static int load_script(const char* path, view_script* out) {
    FILE* f = fopen(path, "rb");
    if (!f) return cli_fail("view", "%s: cannot open the script", path);
    char* buf = malloc(MAX_SCRIPT_SIZE + 1);
    size_t n = buf ? fread(buf, 1, MAX_SCRIPT_SIZE + 1, f) : 0;
    bool err = ferror(f) != 0;
    fclose(f);
    if (!buf || err) {
        free(buf);
        return cli_fail("view", "%s: cannot read the script", path);
    }
    if (n > MAX_SCRIPT_SIZE) {
        free(buf);
        return cli_fail("view", "%s: the script is larger than %u bytes", path, MAX_SCRIPT_SIZE);
    }
    char msg[256];
    int rc = view_script_parse(buf, n, out, msg, sizeof msg);
    free(buf);
    if (rc == CLI_BAD_USAGE) {
        fprintf(stderr, "animkit view: %s: %s\n", path, msg);
        return CLI_BAD_USAGE;
    }
    if (rc) return cli_fail("view", "%s: %s", path, msg);
    return CLI_OK;
}

int cmd_view(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--clip", "-c", true},    {"--size", NULL, true},    {"--script", NULL, true},      {"--headless", NULL, false},
        {"--ik-log", NULL, true},  {"--frames", NULL, true},  {"--supersample", NULL, true}, {"--threads", NULL, true},
        {"--stats", NULL, false},  {"--shot-dir", NULL, true},  {"--seed", NULL, true},
        {"--preset", NULL, true},
    };
    cli_args a;
    int rc = cli_parse("view", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        print_usage();
        return CLI_OK;
    }
    /* `view crowd|rigid --preset P` and `view crowd|rigid SCENE.json` are KIND:preset:P and
     * KIND:SCENE.json */
    char crowd_arg[1100];
    const char* preset = CLI_GET(&a, "--preset");
    const bool kind_first = a.pos_count >= 1 && (strcmp(a.pos[0], "crowd") == 0 || strcmp(a.pos[0], "rigid") == 0);
    if (kind_first && (preset || a.pos_count == 2)) {
        const char* kind = a.pos[0];
        if (preset && a.pos_count == 2) return cli_usage("view", "%s: give a scene file or --preset, not both", kind);
        if (strlen(preset ? preset : a.pos[1]) > 1000) return cli_usage("view", "%s: the scene's name is too long", kind);
        snprintf(crowd_arg, sizeof crowd_arg, preset ? "%s:preset:%s" : "%s:%s", kind, preset ? preset : a.pos[1]);
        a.pos[0] = crowd_arg;
        a.pos_count = 1;
    } else if (preset) {
        return cli_usage("view", "--preset is for `view crowd` and `view rigid` (other simulations: KIND:preset:NAME)");
    }
    if (a.pos_count != 1) return cli_usage("view", "expected one FILE, builtin:NAME or simulation");
    view_options vo = {.width = 960, .height = 600, .clip = -1, .supersample = 1, .threads = 2};
    if (CLI_GET(&a, "--size") && !cli_parse_size(CLI_GET(&a, "--size"), &vo.width, &vo.height))
        return cli_usage("view", "--size '%s' is not WxH with 8..8192 pixels each", CLI_GET(&a, "--size"));
    long v = 0, frames = 1;
    if (CLI_GET(&a, "--supersample")) {
        if (!cli_parse_int(CLI_GET(&a, "--supersample"), 1, 4, &v))
            return cli_usage_int("view", "--supersample", CLI_GET(&a, "--supersample"), 1, 4);
        vo.supersample = (int)v;
    }
    if (CLI_GET(&a, "--threads")) {
        if (!cli_parse_int(CLI_GET(&a, "--threads"), 1, 64, &v))
            return cli_usage_int("view", "--threads", CLI_GET(&a, "--threads"), 1, 64);
        vo.threads = (int)v;
        vo.sim_opts.threads = (int)v;
    }
    if (CLI_GET(&a, "--seed")) {
        const char* s = CLI_GET(&a, "--seed");
        char* end = NULL;
        unsigned long long k = strtoull(s, &end, 10);
        if (!s[0] || s[0] == '-' || s[0] == '+' || *end || (k == ~0ull && strcmp(s, "18446744073709551615") != 0))
            return cli_usage("view", "--seed '%s' is not a whole number in 0..18446744073709551615", s);
        vo.sim_opts.seed = (uint64_t)k;
        vo.sim_opts.has_seed = true;
    }
    if (CLI_GET(&a, "--frames") && !cli_parse_int(CLI_GET(&a, "--frames"), 0, 100000000, &frames))
        return cli_usage_int("view", "--frames", CLI_GET(&a, "--frames"), 0, 100000000);
    bool headless = CLI_GET(&a, "--headless") != NULL;
    if (!headless && !view_window_available())
        return cli_fail("view", "this build has no window (SDL2 was not found at build time); use --headless");
    vo.shot_dir = CLI_GET(&a, "--shot-dir");
    const char* sim_spec = NULL;
    vo.sim = view_sim_find(a.pos[0], &sim_spec);
    vo.sim_spec = sim_spec;
    if (!vo.sim) {
        /* KIND:... with a kind that is not a simulation (builtin:NAME is a model) */
        size_t n = strspn(a.pos[0], "abcdefghijklmnopqrstuvwxyz");
        if (n > 0 && a.pos[0][n] == ':' && strncmp(a.pos[0], "builtin:", 8) != 0)
            return cli_usage("view", "'%.*s' is not a simulation (%s): %s", (int)n, a.pos[0], view_sim_kinds, a.pos[0]);
        if (cli_has_ext(a.pos[0], ".json"))
            return cli_usage("view", "%s: name the simulation of a scene file: particles:%s, boids:%s or cloth:%s",
                             a.pos[0], a.pos[0], a.pos[0], a.pos[0]);
    }

    view_script script = {0};
    const char* script_path = CLI_GET(&a, "--script");
    if (script_path && (rc = load_script(script_path, &script))) return rc;
    vo.scripted = script_path != NULL;
    vo.script_name = script_path;

    ak_scene* s = NULL;
    view_app app;
    memset(&app, 0, sizeof app);
    cli_outfile log; /* --ik-log: a temporary renamed into place when the run succeeds */
    memset(&log, 0, sizeof log);
    if (vo.sim) {
        /* a simulation draws on an empty model scene (no meshes, joints or clips) */
        if (ak_scene_alloc(0, 0, 0, NULL, &s) != AK_OK) {
            rc = cli_fail("view", "out of memory");
            goto done;
        }
        snprintf(s->name, sizeof s->name, "%s", a.pos[0]);
        if (CLI_GET(&a, "--clip") || CLI_GET(&a, "--ik-log")) {
            rc = cli_usage("view", "--clip and --ik-log are for models, not simulations");
            goto done;
        }
    } else if (CLI_GET(&a, "--seed")) {
        rc = cli_usage("view", "--seed is for simulations, not models");
        goto done;
    } else if ((rc = cli_load_scene("view", a.pos[0], &s))) {
        goto done;
    }
    if (CLI_GET(&a, "--clip")) {
        vo.clip = ak_scene_find_clip(s, CLI_GET(&a, "--clip"));
        if (vo.clip < 0) {
            rc = cli_no_clip("view", a.pos[0], CLI_GET(&a, "--clip"), s);
            goto done;
        }
    } else if (s->clip_count) {
        vo.clip = 0;
    }
    if (CLI_GET(&a, "--ik-log") && (rc = cli_outfile_open(&log, "view", CLI_GET(&a, "--ik-log")))) goto done;
    vo.ik_log = log.f;
    if ((rc = view_app_init(&app, s, &vo))) goto done;
    rc = headless ? view_app_run(&app, script_path ? &script : NULL, frames, NULL) : view_window_run(&app, script_path ? &script : NULL);
    if (CLI_GET(&a, "--stats") && app.stats.frames > 0) {
        double k = 1e3 / (double)app.stats.frames;
        double total = app.stats.sample + app.stats.skin + app.stats.raster + app.stats.present;
        fprintf(stderr,
                "view stats: %ld frames %dx%d supersample %d threads %d: sample+FK %.3f ms, skinning %.3f ms, "
                "rasterize %.3f ms, present %.3f ms, total %.3f ms (%.1f fps)\n",
                app.stats.frames, app.width, app.height, vo.supersample, vo.threads, app.stats.sample * k,
                app.stats.skin * k, app.stats.raster * k, app.stats.present * k, total * k,
                total > 0 ? (double)app.stats.frames / total : 0.0);
    }
done:
    if (app.scene) view_app_free(&app);
    if (log.f && rc == CLI_OK) rc = cli_outfile_commit(&log, "view");
    cli_outfile_abort(&log);
    view_script_free(&script);
    ak_scene_destroy(s);
    return rc;
}
