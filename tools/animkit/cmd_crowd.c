/* animkit crowd: walk a crowd with ORCA from a scene file or a preset; JSON, PNG or GIF. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "crowd_draw.h"
#include "outfile.h"

static const char* const usage =
    "usage: animkit crowd [SCENE.json | --preset circle|crossing|corridor|evacuation] [--agents N]\n"
    "                     [--method orca|vision] [--vision-view raycast|raster] [--steps N] [--dt DT]\n"
    "                     [--threads T] [--json OUT.json] [-o OUT.gif|OUT.png|OUT.glb]\n"
    "                     [--size WxH] [--poses exact|shared]\n"
    "People walking to their goals without colliding: ORCA (van den Berg et al. 2011, as RVO2)\n"
    "on the ground plane; see docs/crowd.md for the scene keys. Without a scene or preset it runs\n"
    "the circle preset.\n"
    "  --preset   circle (N agents on a circle, each to the antipode), crossing (four groups walk\n"
    "             across each other), corridor (two groups meet in a corridor), evacuation (a room\n"
    "             empties through one door)\n"
    "  --agents   agents of the preset (default 100; up to 1000000)\n"
    "  --method   orca (default) or vision (synthetic-vision steering, Ondrej et al. 2010)\n"
    "  --vision-view  raycast (default: rays against the neighbours' discs) or raster (each agent's\n"
    "             view rendered by the library's rasterizer, docs/crowd.md)\n"
    "  --steps    steps to run (default: the preset's, long enough for every agent to arrive)\n"
    "  --dt       seconds per step (default 0.1)\n"
    "  --threads  threads per step (default 1; results are identical for any count)\n"
    "  --json     write {\"time\", \"agents\": [{\"position\", \"velocity\", \"goal_reached\"}],\n"
    "             \"min_distance\", \"collisions\"} after the run\n"
    "  -o         .png (the last step) or .gif (the run) rendered, walking characters (builtin:humanoid)\n"
    "             per agent (posed each up to 500 agents, shared poses above); .glb: the run as glTF, a\n"
    "             skinned character per agent (one mesh, a skin each; up to 300 frames, fewer\n"
    "             where the 512 MB bake budget needs it: 10,000 agents get 87)\n"
    "  --size     WxH of the PNG or GIF (default 640x480)\n"
    "  --poses    PNG and GIF characters: exact (each agent posed, feet planted, and skinned) or\n"
    "             shared (one skinned pose per phase bucket, 128 per cycle, drawn under each agent's\n"
    "             root; no foot planting); default exact up to 500 agents, shared above\n"
    "Without --json or -o prints a summary line.\n";

/* ---- collisions: the set of pairs that ever overlapped ------------------------------------ */

typedef struct pair_set {
    uint64_t* keys; /* 0 = empty (pairs are stored + 1) */
    size_t cap, count;
} pair_set;

static bool pair_set_add(pair_set* s, uint64_t key) {
    if (2 * (s->count + 1) > s->cap) {
        const size_t cap = s->cap ? 2 * s->cap : 1024;
        uint64_t* k = calloc(cap, sizeof *k);
        if (!k) return false;
        for (size_t i = 0; i < s->cap; ++i)
            if (s->keys[i]) {
                size_t h = (size_t)((s->keys[i] * 0x9e3779b97f4a7c15ull) >> 20) & (cap - 1);
                while (k[h]) h = (h + 1) & (cap - 1);
                k[h] = s->keys[i];
            }
        free(s->keys);
        s->keys = k;
        s->cap = cap;
    }
    const uint64_t v = key + 1;
    size_t h = (size_t)((v * 0x9e3779b97f4a7c15ull) >> 20) & (s->cap - 1);
    while (s->keys[h]) {
        if (s->keys[h] == v) return true;
        h = (h + 1) & (s->cap - 1);
    }
    s->keys[h] = v;
    ++s->count;
    return true;
}

/* ---- the run -------------------------------------------------------------------------------- */

typedef struct crowd_run {
    ak_crowd* crowd;
    size_t n;
    ak_vec2 *p, *v, *p2, *v2;
    uint32_t* wp;
    uint8_t* scratch;
    uint8_t* cscratch; /* clearance */
    size_t cscratch_size;
    uint32_t* pairs;
    size_t pair_cap;
    ak_crowd_step_job job;
    double min_distance;
    pair_set collided;
} crowd_run;

static void run_free(crowd_run* r) {
    ak_crowd_destroy(r->crowd);
    free(r->p);
    free(r->v);
    free(r->p2);
    free(r->v2);
    free(r->wp);
    free(r->scratch);
    free(r->cscratch);
    free(r->pairs);
    free(r->collided.keys);
}

static void bind(crowd_run* r) {
    r->job.positions = (ak_vec2_cspan){r->p, r->n};
    r->job.velocities = (ak_vec2_cspan){r->v, r->n};
    r->job.waypoints = (ak_u32_span){r->wp, r->n};
    r->job.out_positions = (ak_vec2_span){r->p2, r->n};
    r->job.out_velocities = (ak_vec2_span){r->v2, r->n};
}

/* Clearance and overlapping pairs of the current positions into the run's measures. */
static ak_result measure(crowd_run* r) {
    for (;;) {
        float d = 0.0f;
        size_t over = 0;
        const ak_result res = ak_crowd_clearance(r->crowd, (ak_vec2_cspan){r->p, r->n}, 1e-3f,
                                                 (ak_u8_span){r->cscratch, r->cscratch_size}, &d,
                                                 (ak_u32_span){r->pairs, r->pair_cap}, &over);
        if (res != AK_OK) return res;
        if (2 * over > r->pair_cap) {
            free(r->pairs);
            r->pair_cap = 4 * over + 64;
            r->pairs = malloc(r->pair_cap * sizeof *r->pairs);
            if (!r->pairs) return AK_ERR_NO_MEMORY;
            continue;
        }
        if ((double)d < r->min_distance) r->min_distance = d;
        for (size_t k = 0; k < over; ++k)
            if (!pair_set_add(&r->collided, ((uint64_t)r->pairs[2 * k] << 32) | r->pairs[2 * k + 1]))
                return AK_ERR_NO_MEMORY;
        return AK_OK;
    }
}

static ak_result run_init(crowd_run* r, const ak_crowd_scene* sc, uint32_t threads) {
    memset(r, 0, sizeof *r);
    r->min_distance = INFINITY;
    ak_crowd_desc d = {.agents = {sc->agents, sc->agent_count}, .obstacles = sc->obstacles,
                       .obstacle_count = (uint32_t)sc->obstacle_count,
                       .method = sc->method, .vision_view = sc->vision_view};
    ak_result res = ak_crowd_create(&d, NULL, &r->crowd);
    if (res != AK_OK) return res;
    const size_t n = r->n = sc->agent_count;
    r->p = malloc(n * sizeof *r->p);
    r->v = malloc(n * sizeof *r->v);
    r->p2 = malloc(n * sizeof *r->p2);
    r->v2 = malloc(n * sizeof *r->v2);
    r->wp = calloc(n, sizeof *r->wp);
    r->cscratch_size = ak_crowd_clearance_scratch_size(r->crowd, n);
    r->cscratch = malloc(r->cscratch_size);
    r->pair_cap = 256;
    r->pairs = malloc(r->pair_cap * sizeof *r->pairs);
    if (!r->p || !r->v || !r->p2 || !r->v2 || !r->wp || !r->cscratch || !r->pairs) return AK_ERR_NO_MEMORY;
    memcpy(r->p, sc->positions, n * sizeof *r->p);
    memcpy(r->v, sc->velocities, n * sizeof *r->v);
    r->job = (ak_crowd_step_job){.crowd = r->crowd, .dt = sc->dt, .thread_count = threads,
                                 .contact_iterations = sc->contact_iterations};
    bind(r);
    const size_t bytes = ak_crowd_step_scratch_size(&r->job);
    r->scratch = malloc(bytes ? bytes : 1);
    if (!r->scratch) return AK_ERR_NO_MEMORY;
    r->job.scratch = (ak_u8_span){r->scratch, bytes};
    return measure(r);
}

static ak_result run_step(crowd_run* r, long s) {
    r->job.step_index = (uint64_t)s;
    ak_result res = ak_crowd_step_run(&r->job);
    if (res != AK_OK) return res;
    ak_vec2* t = r->p;
    r->p = r->p2;
    r->p2 = t;
    t = r->v;
    r->v = r->v2;
    r->v2 = t;
    bind(r);
    return measure(r);
}

static size_t reached_count(const crowd_run* r) {
    size_t k = 0;
    for (size_t i = 0; i < r->n; ++i) k += ak_crowd_goal_reached(r->crowd, i, r->p[i], r->wp[i]);
    return k;
}

/* The one memory budget of the glTF crowd: the bake (ak_crowd_bake_max_frames, ak_crowd_bake_scene)
 * and the writer (ak_io_save: the file's bytes) are each held to it. */
#define CROWD_GLTF_BUDGET AK_SCENE_BAKE_DEFAULT_BUDGET

/* The recorded run as glTF: a skinned character per agent (ak_crowd_bake_scene). */
static int chars_write_gltf(crowd_chars* c, const ak_crowd_scene* sc, float frame_time, const char* out) {
    ak_vec4* colors = malloc(c->n * sizeof *colors);
    if (!colors) return cli_fail("crowd", "out of memory");
    for (size_t i = 0; i < c->n; ++i) colors[i] = crowd_palette[sc->group[i] % 4];
    ak_crowd_bake_desc bd = {.gait = &c->gait, .agent_count = c->n, .frame_count = c->frames,
                             .positions = c->rec_pos, .characters = c->rec_ch, .frame_time = frame_time,
                             .colors = colors, .name = "crowd", .memory_budget = CROWD_GLTF_BUDGET};
    ak_scene* baked = NULL;
    ak_diag diag = {0};
    ak_result r = ak_crowd_bake_scene(&bd, NULL, &baked, &diag);
    free(colors);
    if (r != AK_OK) return cli_fail("crowd", "%s: %s", out, diag.message[0] ? diag.message : ak_result_string(r));
    const ak_io_save_desc sd = {.memory_budget = CROWD_GLTF_BUDGET};
    r = ak_io_save(out, baked, &sd, &diag);
    ak_scene_destroy(baked);
    if (r != AK_OK) return cli_fail("crowd", "%s: %s", out, diag.message[0] ? diag.message : ak_result_string(r));
    return CLI_OK;
}

/* ---- rendering ------------------------------------------------------------------------------ */

typedef struct renderer {
    int w, h;
    ak_raster* raster;
    ak_raster_camera cam;
    ak_vec3 center;
    float extent;
    crowd_people people;
    ak_vec3* wall;
    size_t wall_count; /* vertices */
    uint8_t* pixels;
} renderer;

static void renderer_free(renderer* r) {
    ak_raster_destroy(r->raster);
    crowd_people_free(&r->people);
    free(r->wall);
    free(r->pixels);
}

static int renderer_init(renderer* r, int w, int h, const ak_crowd_scene* sc, const crowd_chars* chars, bool shared) {
    memset(r, 0, sizeof *r);
    r->w = w;
    r->h = h;
    ak_raster_desc d = {.width = w, .height = h, .supersample = 2, .thread_count = 2};
    if (ak_raster_create(&d, NULL, &r->raster) != AK_OK) return 1;
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < sc->agent_count; ++i) {
        const ak_vec2 p = sc->positions[i], g = sc->agents[i].goals.ptr[sc->agents[i].goals.count - 1];
        lo[0] = fminf(lo[0], fminf(p.x, g.x));
        lo[1] = fminf(lo[1], fminf(p.y, g.y));
        hi[0] = fmaxf(hi[0], fmaxf(p.x, g.x));
        hi[1] = fmaxf(hi[1], fmaxf(p.y, g.y));
    }
    r->center = ak_vec3_make(0.5f * (lo[0] + hi[0]), 0.0f, 0.5f * (lo[1] + hi[1]));
    r->extent = fmaxf(3.0f, 0.5f * hypotf(hi[0] - lo[0], hi[1] - lo[1]));
    const ak_vec3 eye = ak_vec3_add(r->center, ak_vec3_make(0.0f, 1.5f * r->extent, 1.1f * r->extent));
    r->cam = ak_raster_camera_perspective(eye, r->center, ak_radians(45), (float)w / (float)h, 0.05f * r->extent,
                                          10.0f * r->extent);
    r->pixels = malloc((size_t)w * (size_t)h * 4);
    if (!r->pixels || !(shared ? crowd_people_init_shared(&r->people, sc->agent_count, chars)
                               : crowd_people_init(&r->people, sc->agent_count, chars)))
        return 1;
    return crowd_walls(sc, &r->wall, &r->wall_count) ? 0 : 1;
}

/* The agents' characters and the walls, over the ground with shadows. */
static ak_result draw_frame(renderer* r, const ak_crowd_scene* sc, const crowd_run* st, crowd_chars* chars,
                            ak_image* out) {
    ak_raster_mesh people;
    ak_result res = crowd_people_update(&r->people, sc, st->p, chars, &people);
    if (res != AK_OK) return res;
    crowd_people* pp = &r->people;
    const size_t k = pp->shared ? pp->n : people.positions.count;
    ak_raster_mesh walls = {.positions = {r->wall, r->wall_count}, .material = {.color = {0.6f, 0.6f, 0.62f, 1}}};
    ak_raster_mesh casters[2] = {people, walls};
    if (pp->shared) pp->casters[pp->n] = walls; /* every agent's bucket mesh, then the walls */
    ak_raster_clear(r->raster, ak_vec4_make(0.80f, 0.86f, 0.93f, 1), ak_vec4_make(0.55f, 0.60f, 0.68f, 1));
    ak_raster_ground g = {.height = 0.0f, .center = r->center, .half_extent = 1.6f * r->extent,
                          .casters = pp->shared ? pp->casters : casters,
                          .caster_count = (pp->shared ? pp->n : 1) + (r->wall_count ? 1 : 0)};
    res = k ? ak_raster_draw_ground(r->raster, &r->cam, &g) : AK_OK;
    if (res == AK_OK && r->wall_count) res = ak_raster_draw_mesh(r->raster, &r->cam, &walls);
    if (res == AK_OK && k) res = crowd_people_draw(pp, r->raster, &r->cam, &people);
    if (res == AK_OK) res = ak_raster_resolve(r->raster, out);
    return res;
}

/* ---- the command -------------------------------------------------------------------------- */

static int write_json(const char* path, double time, const crowd_run* st) {
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "crowd", path)) return CLI_BAD_INPUT;
    FILE* f = out.f;
    fprintf(f, "{\"time\": %.9g, \"agents\": [", time);
    for (size_t i = 0; i < st->n; ++i)
        fprintf(f, "%s{\"position\": [%.9g, %.9g], \"velocity\": [%.9g, %.9g], \"goal_reached\": %s}", i ? ", " : "",
                (double)st->p[i].x, (double)st->p[i].y, (double)st->v[i].x, (double)st->v[i].y,
                ak_crowd_goal_reached(st->crowd, i, st->p[i], st->wp[i]) ? "true" : "false");
    /* one agent: no pair, no distance (JSON has no infinity): null */
    if (st->n >= 2) fprintf(f, "], \"min_distance\": %.9g", st->min_distance);
    else fprintf(f, "], \"min_distance\": null");
    fprintf(f, ", \"collisions\": %zu}\n", st->collided.count);
    return cli_outfile_commit(&out, "crowd");
}

int cmd_crowd(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--agents", NULL, true}, {"--steps", NULL, true},  {"--dt", NULL, true},     {"--threads", NULL, true},
        {"--json", NULL, true},   {"--output", "-o", true}, {"--preset", NULL, true}, {"--method", NULL, true}, {"--vision-view", NULL, true},
        {"--size", NULL, true},   {"--poses", NULL, true},
    };
    cli_args a;
    int rc = cli_parse("crowd", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count > 1) return cli_usage("crowd", "expected at most one SCENE.json");
    const char* preset = CLI_GET(&a, "--preset");
    if (preset && a.pos_count == 1) return cli_usage("crowd", "give a scene file or --preset, not both");
    const char* method = CLI_GET(&a, "--method");
    const char* vview = CLI_GET(&a, "--vision-view");
    if (vview && strcmp(vview, "raycast") != 0 && strcmp(vview, "raster") != 0)
        return cli_usage("crowd", "--vision-view '%s' must be raycast or raster", vview);
    if (method && strcmp(method, "orca") != 0 && strcmp(method, "vision") != 0)
        return cli_usage("crowd", "--method '%s' must be orca or vision", method);
    const char* poses = CLI_GET(&a, "--poses");
    if (poses && strcmp(poses, "exact") != 0 && strcmp(poses, "shared") != 0)
        return cli_usage("crowd", "--poses '%s' must be exact or shared", poses);
    long agents = 0, steps = -1, threads = 1;
    float dt = -1.0f;
    int w = 640, h = 480;
    if (CLI_GET(&a, "--agents") && !cli_parse_int(CLI_GET(&a, "--agents"), 1, AK_CROWD_SCENE_MAX_AGENTS, &agents))
        return cli_usage_int("crowd", "--agents", CLI_GET(&a, "--agents"), 1, AK_CROWD_SCENE_MAX_AGENTS);
    if (CLI_GET(&a, "--steps") && !cli_parse_int(CLI_GET(&a, "--steps"), 0, 100000000, &steps))
        return cli_usage_int("crowd", "--steps", CLI_GET(&a, "--steps"), 0, 100000000);
    if (CLI_GET(&a, "--threads") && !cli_parse_int(CLI_GET(&a, "--threads"), 1, 64, &threads))
        return cli_usage_int("crowd", "--threads", CLI_GET(&a, "--threads"), 1, 64);
    if (CLI_GET(&a, "--dt") && (!cli_parse_float(CLI_GET(&a, "--dt"), &dt) || !(dt >= 1e-4f) || dt > 10.0f))
        return cli_usage("crowd", "--dt '%s' is not a number in [0.0001, 10] (seconds)", CLI_GET(&a, "--dt"));
    if (CLI_GET(&a, "--size") && (!cli_parse_size(CLI_GET(&a, "--size"), &w, &h) || w > 4096 || h > 4096))
        return cli_usage("crowd", "--size '%s' is not WxH (at most 4096x4096)", CLI_GET(&a, "--size"));
    const char* out = CLI_GET(&a, "--output");
    const char* json = CLI_GET(&a, "--json");
    if (out && !cli_has_ext(out, ".png") && !cli_has_ext(out, ".gif") && !cli_has_ext(out, ".glb"))
        return cli_usage("crowd", "output '%s' must end in .png, .gif or .glb", out);
    if (a.pos_count == 1 && agents > 0) return cli_usage("crowd", "--agents sets a preset's size; the scene lists its agents");

    ak_crowd_scene sc;
    ak_diag diag;
    if (a.pos_count == 1) {
        ak_crowd_scene_defaults(&sc);
        if (ak_crowd_scene_load_file(a.pos[0], &sc, &diag) != AK_OK) {
            ak_crowd_scene_free(&sc);
            return cli_fail("crowd", "%s", diag.message);
        }
    } else {
        const ak_result pr = ak_crowd_scene_preset(preset ? preset : "circle", (size_t)agents, &sc, &diag);
        if (pr == AK_ERR_NOT_FOUND)
            return cli_usage("crowd", "--preset '%s' must be one of " AK_CROWD_SCENE_PRESETS, preset);
        if (pr != AK_OK) return cli_fail("crowd", "%s", diag.message);
    }
    if (dt > 0.0f) {
        sc.dt = dt;
        if (sc.duration > 0.0f) sc.steps = (long)ceilf(sc.duration / dt); /* a preset's run at this dt */
    }
    if (steps >= 0) sc.steps = steps;
    if (method) sc.method = strcmp(method, "vision") == 0 ? AK_CROWD_VISION : AK_CROWD_ORCA;
    if (vview) sc.vision_view = strcmp(vview, "raster") == 0 ? AK_CROWD_VIEW_RASTER : AK_CROWD_VIEW_RAYCAST;
    const bool is_glb = out && cli_has_ext(out, ".glb"), is_gif = out && cli_has_ext(out, ".gif");
    if ((rc = cli_work_check("crowd", (double)sc.agent_count * (double)sc.steps, "agent updates (agents x steps)",
                             "--steps or --agents"))) {
        ak_crowd_scene_free(&sc);
        return rc;
    }
    crowd_run st;
    ak_result res = run_init(&st, &sc, (uint32_t)threads);
    if (res != AK_OK) {
        run_free(&st);
        ak_crowd_scene_free(&sc);
        return cli_fail("crowd", "%s: %s", a.pos_count ? a.pos[0] : "preset", ak_result_string(res));
    }
    crowd_chars chars;
    memset(&chars, 0, sizeof chars);
    const bool with_chars = is_glb || out;
    const bool shared_poses = !is_glb && (poses ? strcmp(poses, "shared") == 0 : sc.agent_count > CROWD_CHARACTERS_MAX);
    /* Frames: at most 150 in a GIF; in a glTF file at most 300, and as many as the bake's memory
     * budget holds for this many agents (refused before the run when not even one fits). */
    long max_frames = is_glb ? 300 : 150, every = 1;
    if (with_chars) {
        ak_diag cd = {0};
        res = crowd_chars_init(&chars, &sc, 0, &cd);
        chars.unplanted = shared_poses; /* shared poses have no foot planting */
        if (res == AK_OK && is_glb) {
            const size_t fit = ak_crowd_bake_max_frames(&chars.gait, sc.agent_count, CROWD_GLTF_BUDGET);
            if (fit == 0) {
                const size_t n = sc.agent_count;
                crowd_chars_free(&chars);
                run_free(&st);
                ak_crowd_scene_free(&sc);
                return cli_fail("crowd", "%s: %zu agents: not one frame of the glTF crowd fits (its memory budget of "
                                "%zu MB, at most %u nodes; use --agents)", out, n,
                                (size_t)CROWD_GLTF_BUDGET >> 20, AK_SKELETON_MAX_JOINTS);
            }
            if ((long)fit < max_frames) max_frames = (long)fit;
        }
        if (!is_glb) every = sc.steps > max_frames ? (sc.steps + max_frames - 1) / max_frames : 1;
        else if (max_frames < 2) every = sc.steps + 1; /* one frame */
        else /* the frames recorded, steps / every + 1, are at most max_frames */
            every = sc.steps > max_frames - 1 ? (sc.steps + max_frames - 2) / (max_frames - 1) : 1;
        if (res == AK_OK && is_glb) res = crowd_chars_record_reserve(&chars, (size_t)(sc.steps / every + 1));
        if (res != AK_OK) {
            crowd_chars_free(&chars);
            run_free(&st);
            ak_crowd_scene_free(&sc);
            return cli_fail("crowd", "characters: %s", cd.message[0] ? cd.message : ak_result_string(res));
        }
    }

    renderer rd;
    ak_gif_writer* gif = NULL;
    ak_image img = {0};
    const bool rendering = out != NULL && !is_glb;
    if (rendering) {
        if (renderer_init(&rd, w, h, &sc, &chars, shared_poses)) {
            renderer_free(&rd);
            crowd_chars_free(&chars);
            run_free(&st);
            ak_crowd_scene_free(&sc);
            return cli_fail("crowd", "out of memory for rendering");
        }
        img = (ak_image){.pixels = rd.pixels, .width = w, .height = h};
        if (is_gif && ak_gif_writer_create(out, &(ak_gif_desc){.width = w, .height = h, .delay_cs = 4}, NULL, &gif) != AK_OK) {
            renderer_free(&rd);
            crowd_chars_free(&chars);
            run_free(&st);
            ak_crowd_scene_free(&sc);
            return cli_fail("crowd", "%s: cannot create the file", out);
        }
    }
    crowd_chars* cp = with_chars ? &chars : NULL;
    const double t0 = cli_now();
    long failed_step = -1, done = 0;
    ak_result wres = AK_OK;
    for (long s = 0; s <= sc.steps && res == AK_OK && wres == AK_OK; ++s) {
        if (gif && s % every == 0) {
            res = draw_frame(&rd, &sc, &st, cp, &img);
            if (res == AK_OK) wres = ak_gif_writer_add_frame(gif, &img);
        }
        if (is_glb && s % every == 0) crowd_chars_record(&chars, st.p);
        if (s == sc.steps) break;
        if (res == AK_OK && (res = run_step(&st, s)) != AK_OK) failed_step = s;
        else done = s + 1;
        if (res == AK_OK && cp && (res = crowd_chars_update(cp, st.v, st.p, sc.dt)) != AK_OK) failed_step = s;
        cli_progress("crowd", (size_t)s + 1, (size_t)sc.steps);
    }
    const double elapsed = cli_now() - t0;
    if (res == AK_OK && rendering && !is_gif) {
        res = draw_frame(&rd, &sc, &st, cp, &img);
        if (res == AK_OK) wres = ak_png_write(out, &img);
    }
    if (gif && (res != AK_OK || wres != AK_OK)) ak_gif_writer_discard(gif); /* no partial GIF */
    else if (gif) wres = ak_gif_writer_finish(gif);
    if (rendering) renderer_free(&rd);
    rc = CLI_OK;
    if (res != AK_OK && failed_step >= 0) rc = cli_fail("crowd", "step %ld: %s", failed_step, ak_result_string(res));
    else if (res != AK_OK) rc = cli_fail("crowd", "%s", ak_result_string(res));
    else if (wres != AK_OK) rc = cli_fail("crowd", "%s: cannot write the file: %s", out, ak_result_string(wres));
    if (rc == CLI_OK && is_glb) rc = chars_write_gltf(&chars, &sc, (float)every * sc.dt, out);
    crowd_chars_free(&chars);
    const size_t reached = reached_count(&st);
    if (rc == CLI_OK && out)
        cli_wrote(out, "%zu agents after %ld steps%s", st.n, done,
                  is_glb ? " (a skinned character each)" : (with_chars ? " (characters)" : ""));
    if (rc == CLI_OK && json && (rc = write_json(json, (double)((float)done * sc.dt), &st)) == CLI_OK)
        cli_wrote(json, "%zu agents after %ld steps, %zu at their goal", st.n, done, reached);
    if (rc == CLI_OK && !json && !out)
        printf("crowd: %zu agents, %ld steps in %.3f s (%.3f ms/step), %zu at their goal, min distance %.4g m, "
               "%zu collisions\n",
               st.n, done, elapsed, done ? 1e3 * elapsed / (double)done : 0.0, reached, st.min_distance,
               st.collided.count);
    run_free(&st);
    ak_crowd_scene_free(&sc);
    return rc;
}
