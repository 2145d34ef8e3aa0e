/* animkit boids: run a flock from a scene file (or defaults), write JSON and/or render it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_json.h"
#include "scene_boids.h"

static const char* const usage =
    "usage: animkit boids [SCENE.json] [--count N] [--steps S] [--dt DT] [--seed K] [--threads T] [--2d]\n"
    "                     [--json OUT.json] [-o OUT.gif|OUT.png] [--size WxH]\n"
    "Reynolds flocking (separation, alignment, cohesion with a view cone and a k-nearest cap),\n"
    "obstacles, bounds, goal, leader, predators and wander; see docs/boids.md for the scene keys.\n"
    "  --count    agents placed at random in the bounds when the scene has no \"agents\" (default 500)\n"
    "  --steps    steps to run (default 200)        --dt  seconds per step (default 0.02)\n"
    "  --seed     random placement and wander (default 1)\n"
    "  --threads  threads per step (default 1; results are identical for any count)\n"
    "  --2d       agents on the horizontal plane y = 0 (same as \"planar\": true)\n"
    "  --json     write {\"steps\", \"agents\": [{\"p\", \"v\"}], \"order\", \"min_distance\"} after the run\n"
    "  -o         render the flock: .png (last step) or .gif (the run), --size WxH (default 640x480)\n"
    "Without --json or -o prints a summary line.\n";

typedef struct run_state {
    size_t n;
    ak_vec3 *p, *v, *p2, *v2, *w;
    uint8_t* s;
    uint8_t* scratch;
    size_t scratch_size;
} run_state;

static void run_free(run_state* r) {
    free(r->p);
    free(r->v);
    free(r->p2);
    free(r->v2);
    free(r->w);
    free(r->s);
    free(r->scratch);
}

/* ---- rendering ---------------------------------------------------------------------------- */

typedef struct renderer {
    int w, h;
    ak_raster* raster;
    ak_raster_camera cam;
    ak_vec3 center;
    float extent;
    float ground_y;
    ak_vec3* pos;   /* agent shapes: 5 vertices per agent */
    ak_vec4* col;
    uint32_t* idx;  /* 4 triangles per agent */
    ak_vec3* opos;  /* obstacles */
    uint32_t* oidx;
    size_t overt, otri;
    uint8_t* pixels;
    ak_clip* beat;  /* the wing-beat (or tail-sway) clip: one scalar channel, looped */
} renderer;

/* The flap: one scalar channel in [-1, 1] over a third of a second (wings up, a slow
 * downstroke, a quick recovery), Catmull-Rom through the keys. Each agent samples it at its
 * own phase. */
static ak_clip* make_beat_clip(void) {
    static const float times[] = {0.0f, 0.06f, 0.19f, 0.27f, 1.0f / 3.0f};
    static const float values[] = {1.0f, 0.7f, -1.0f, -0.3f, 1.0f};
    const ak_raw_channel ch = {.target = AK_CHANNEL_SCALAR, .index = 0, .component_count = 1,
                               .interp = AK_INTERP_CARDINAL, .key_count = 5, .times = times, .values = values};
    const ak_raw_clip raw = {.name = "beat", .channels = &ch, .channel_count = 1, .scalar_count = 1};
    ak_clip* clip = NULL;
    return ak_clip_build(&raw, NULL, &clip, NULL) == AK_OK ? clip : NULL;
}

/* A plane facing up: the renderer's ground plane shows it. */
static bool is_floor(const ak_boids_obstacle* o) {
    return o->kind == AK_BOIDS_PLANE && ak_vec3_normalize(o->normal).y > 0.999f;
}

/* Unit sphere (lat-long) and box triangles appended to the obstacle mesh. */
static void add_obstacles(renderer* r, const ak_boids_params* prm, float plane_size) {
    enum { LAT = 10, LON = 16 };
    size_t nv = 0, nt = 0;
    for (uint32_t k = 0; k < prm->obstacle_count; ++k) {
        const ak_boids_obstacle* o = &prm->obstacles[k];
        if (o->kind == AK_BOIDS_SPHERE) {
            nv += (LAT + 1) * (LON + 1);
            nt += LAT * LON * 2;
        } else {
            nv += 8;
            nt += 12;
        }
    }
    r->opos = malloc((nv + 1) * sizeof(ak_vec3));
    r->oidx = malloc((nt + 1) * 3 * sizeof(uint32_t));
    if (!r->opos || !r->oidx) return;
    size_t v = 0, t = 0;
    for (uint32_t k = 0; k < prm->obstacle_count; ++k) {
        const ak_boids_obstacle* o = &prm->obstacles[k];
        const uint32_t base = (uint32_t)v;
        if (is_floor(o)) continue; /* drawn as the ground itself */
        if (o->kind == AK_BOIDS_SPHERE) {
            for (int a = 0; a <= LAT; ++a)
                for (int b = 0; b <= LON; ++b) {
                    const float th = AK_PI * (float)a / LAT, ph = AK_TWO_PI * (float)b / LON;
                    r->opos[v++] = ak_vec3_madd(o->center, ak_vec3_make(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph)),
                                                o->radius);
                }
            for (int a = 0; a < LAT; ++a)
                for (int b = 0; b < LON; ++b) {
                    const uint32_t i0 = base + (uint32_t)(a * (LON + 1) + b), i1 = i0 + 1, i2 = i0 + LON + 1, i3 = i2 + 1;
                    const uint32_t tri[6] = {i0, i1, i2, i1, i3, i2};
                    memcpy(r->oidx + 3 * t, tri, sizeof tri);
                    t += 2;
                }
            continue;
        }
        ak_vec3 c = o->center, h = o->half_extents;
        ak_vec3 ax = ak_vec3_make(1, 0, 0), ay = ak_vec3_make(0, 1, 0), az = ak_vec3_make(0, 0, 1);
        if (o->kind == AK_BOIDS_PLANE) {
            /* A thin slab along the plane, drawn as a box. */
            ay = ak_vec3_normalize(o->normal);
            ax = ak_vec3_normalize(ak_vec3_any_perpendicular(ay));
            az = ak_vec3_cross(ax, ay);
            h = ak_vec3_make(plane_size, 0.02f * plane_size, plane_size);
            c = ak_vec3_madd(c, ay, -h.y);
        }
        for (int q = 0; q < 8; ++q) {
            ak_vec3 p = c;
            p = ak_vec3_madd(p, ax, (q & 1) ? h.x : -h.x);
            p = ak_vec3_madd(p, ay, (q & 2) ? h.y : -h.y);
            p = ak_vec3_madd(p, az, (q & 4) ? h.z : -h.z);
            r->opos[v++] = p;
        }
        static const uint32_t faces[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                           2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
        for (int q = 0; q < 36; ++q) r->oidx[3 * t + (size_t)q] = base + faces[q];
        t += 12;
    }
    r->overt = v;
    r->otri = t;
}

static int renderer_init(renderer* r, int w, int h, const cli_boids_scene* sc, size_t n) {
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
        if (is_floor(&prm->obstacles[k])) r->ground_y = prm->obstacles[k].center.y;
    const ak_vec3 eye = ak_vec3_add(r->center, ak_vec3_make(0.9f * r->extent, (prm->planar ? 1.6f : 0.9f) * r->extent,
                                                             1.5f * r->extent));
    r->cam = ak_raster_camera_perspective(eye, r->center, ak_radians(45), (float)w / (float)h, 0.05f * r->extent,
                                          10.0f * r->extent);
    r->pos = malloc(n * 5 * sizeof(ak_vec3));
    r->col = malloc(n * 5 * sizeof(ak_vec4));
    r->idx = malloc(n * 12 * sizeof(uint32_t));
    r->pixels = malloc((size_t)w * (size_t)h * 4);
    if (!r->pos || !r->col || !r->idx || !r->pixels) return 1;
    for (size_t i = 0; i < n; ++i) {
        const uint32_t b = (uint32_t)(5 * i);
        const uint32_t tri[12] = {b, b + 1, b + 2, b, b + 2, b + 3, b, b + 4, b + 2, b + 1, b + 4, b + 3};
        memcpy(r->idx + 12 * i, tri, sizeof tri);
    }
    add_obstacles(r, prm, r->extent);
    r->beat = make_beat_clip();
    return r->beat ? 0 : 1;
}

static void renderer_free(renderer* r) {
    ak_raster_destroy(r->raster);
    free(r->pos);
    free(r->col);
    free(r->idx);
    free(r->opos);
    free(r->oidx);
    free(r->pixels);
    ak_clip_destroy(r->beat);
}

/* One frame: every agent a small bird (a body and two wings that flap) or fish (a body whose
 * tail sways), aligned with its velocity, animated by the beat clip at the agent's own phase. */
static ak_result draw_frame(renderer* r, const cli_boids_scene* sc, const run_state* st, float time, ak_image* out) {
    const float L = sc->shape_size;
    for (size_t i = 0; i < st->n; ++i) {
        ak_vec3 f = ak_vec3_normalize(st->v[i]);
        if (ak_vec3_length_sq(f) < 0.5f) f = ak_vec3_make(0, 0, 1);
        ak_vec3 right = ak_vec3_normalize(ak_vec3_cross(f, ak_vec3_make(0, 1, 0)));
        if (ak_vec3_length_sq(right) < 0.5f) right = ak_vec3_make(1, 0, 0);
        const ak_vec3 up = ak_vec3_cross(right, f);
        const float phase = (float)((i * 2654435761u) & 1023u) / 1024.0f;
        const float period = ak_clip_duration(r->beat);
        float beat = 0.0f;
        ak_clip_sample(r->beat, ak_time_wrap(time + phase * period, period, AK_WRAP_LOOP), NULL,
                       (ak_transform_span){NULL, 0}, (ak_f32_span){NULL, 0}, (ak_f32_span){&beat, 1});
        const ak_vec3 p = st->p[i];
        ak_vec3* q = r->pos + 5 * i;
        if (sc->shape == 0) {
            q[0] = ak_vec3_madd(p, f, 0.5f * L);                                       /* beak */
            q[1] = ak_vec3_madd(ak_vec3_madd(p, right, -0.5f * L), up, 0.25f * L * beat); /* left wing tip */
            q[2] = ak_vec3_madd(p, f, -0.5f * L);                                      /* tail */
            q[3] = ak_vec3_madd(ak_vec3_madd(p, right, 0.5f * L), up, 0.25f * L * beat);  /* right wing tip */
            q[4] = ak_vec3_madd(p, up, -0.12f * L);                                    /* keel */
        } else {
            const ak_vec3 tail = ak_vec3_madd(ak_vec3_madd(p, f, -0.5f * L), right, 0.15f * L * beat);
            q[0] = ak_vec3_madd(p, f, 0.5f * L);
            q[1] = ak_vec3_madd(p, right, -0.08f * L);
            q[2] = tail;
            q[3] = ak_vec3_madd(p, right, 0.08f * L);
            q[4] = ak_vec3_madd(p, up, 0.18f * L);
        }
        const ak_vec4 c = sc->color[st->s[i]];
        for (int k = 0; k < 5; ++k) r->col[5 * i + (size_t)k] = c;
    }
    ak_raster_mesh birds = {.positions = {r->pos, 5 * st->n}, .colors = {r->col, 5 * st->n},
                            .indices = {r->idx, 12 * st->n}, .shading = AK_SHADING_FLAT,
                            .material = {.color = {1, 1, 1, 1}, .specular = -1}};
    ak_raster_mesh obs = {.positions = {r->opos, r->overt}, .indices = {r->oidx, 3 * r->otri},
                          .material = {.color = {0.62f, 0.64f, 0.68f, 1}}};
    ak_raster_mesh casters[2] = {birds, obs};
    ak_raster_clear(r->raster, ak_vec4_make(0.80f, 0.86f, 0.93f, 1), ak_vec4_make(0.55f, 0.60f, 0.68f, 1));
    ak_raster_ground g = {.height = r->ground_y, .center = r->center, .half_extent = 1.6f * r->extent,
                          .casters = casters, .caster_count = r->otri ? 2 : 1};
    ak_result res = ak_raster_draw_ground(r->raster, &r->cam, &g);
    if (res == AK_OK && r->otri) res = ak_raster_draw_mesh(r->raster, &r->cam, &obs);
    if (res == AK_OK) res = ak_raster_draw_mesh(r->raster, &r->cam, &birds);
    if (res == AK_OK) res = ak_raster_resolve(r->raster, out);
    return res;
}

/* ---- the command -------------------------------------------------------------------------- */

static int write_json(const char* path, long steps, const run_state* st) {
    FILE* f = fopen(path, "w");
    if (!f) return cli_fail("boids", "%s: cannot write", path);
    const float order = ak_boids_order((ak_vec3_cspan){st->v, st->n});
    float dmin = 0.0f;
    if (st->n >= 2) {
        const size_t bytes = ak_boids_min_distance_scratch_size(st->n);
        uint8_t* scr = malloc(bytes);
        if (!scr || ak_boids_min_distance((ak_vec3_cspan){st->p, st->n}, (ak_u8_span){scr, bytes}, &dmin) != AK_OK)
            dmin = 0.0f;
        free(scr);
    }
    fprintf(f, "{\"steps\": %ld, \"agents\": [", steps);
    for (size_t i = 0; i < st->n; ++i)
        fprintf(f, "%s{\"p\": [%.9g, %.9g, %.9g], \"v\": [%.9g, %.9g, %.9g]}", i ? ", " : "", (double)st->p[i].x,
                (double)st->p[i].y, (double)st->p[i].z, (double)st->v[i].x, (double)st->v[i].y, (double)st->v[i].z);
    fprintf(f, "], \"order\": %.9g, \"min_distance\": %.9g}\n", (double)order, (double)dmin);
    if (fclose(f) != 0) return cli_fail("boids", "%s: cannot write", path);
    return CLI_OK;
}

int cmd_boids(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--count", NULL, true},   {"--steps", NULL, true}, {"--dt", NULL, true},   {"--seed", NULL, true},
        {"--threads", NULL, true}, {"--2d", NULL, false},   {"--json", NULL, true}, {"--output", "-o", true},
        {"--size", NULL, true},
    };
    cli_args a;
    int rc = cli_parse("boids", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count > 1) return cli_usage("boids", "expected at most one SCENE.json");
    long count = -1, steps = -1, seed = -1, threads = 1;
    float dt = -1.0f;
    int w = 640, h = 480;
    if (CLI_GET(&a, "--count") && !cli_parse_int(CLI_GET(&a, "--count"), 1, CLI_BOIDS_MAX_AGENTS, &count))
        return cli_usage("boids", "--count '%s' is not a whole number in [1, %u]", CLI_GET(&a, "--count"),
                         CLI_BOIDS_MAX_AGENTS);
    if (CLI_GET(&a, "--steps") && !cli_parse_int(CLI_GET(&a, "--steps"), 0, 100000000, &steps))
        return cli_usage("boids", "--steps '%s' is not a whole number >= 0", CLI_GET(&a, "--steps"));
    if (CLI_GET(&a, "--seed") && !cli_parse_int(CLI_GET(&a, "--seed"), 0, 2147483647, &seed))
        return cli_usage("boids", "--seed '%s' is not a whole number >= 0", CLI_GET(&a, "--seed"));
    if (CLI_GET(&a, "--threads") && !cli_parse_int(CLI_GET(&a, "--threads"), 1, 64, &threads))
        return cli_usage("boids", "--threads '%s' is not a whole number in [1, 64]", CLI_GET(&a, "--threads"));
    if (CLI_GET(&a, "--dt") && (!cli_parse_float(CLI_GET(&a, "--dt"), &dt) || !(dt > 0.0f) || dt > 10.0f))
        return cli_usage("boids", "--dt '%s' is not a number in (0, 10]", CLI_GET(&a, "--dt"));
    if (CLI_GET(&a, "--size") && (!cli_parse_size(CLI_GET(&a, "--size"), &w, &h) || w > 4096 || h > 4096))
        return cli_usage("boids", "--size '%s' is not WxH (at most 4096x4096)", CLI_GET(&a, "--size"));
    const char* out = CLI_GET(&a, "--output");
    const char* json = CLI_GET(&a, "--json");
    if (out && !cli_has_ext(out, ".png") && !cli_has_ext(out, ".gif"))
        return cli_usage("boids", "output '%s' must end in .png or .gif", out);

    cli_boids_scene sc;
    cli_boids_scene_defaults(&sc);
    if (a.pos_count == 1) {
        FILE* f = fopen(a.pos[0], "rb");
        if (!f) return cli_fail("boids", "%s: cannot open the file", a.pos[0]);
        char* text = NULL;
        size_t size = 0, cap = 0;
        for (;;) {
            if (size == cap) {
                if (cap > CLI_JSON_MAX_SIZE) break;
                cap = cap ? cap * 2 : 65536;
                char* g = realloc(text, cap + 1);
                if (!g) break;
                text = g;
            }
            const size_t got = fread(text + size, 1, cap - size, f);
            size += got;
            if (got == 0) break;
        }
        fclose(f);
        if (!text) return cli_fail("boids", "%s: out of memory", a.pos[0]);
        if (size > CLI_JSON_MAX_SIZE) {
            free(text);
            return cli_fail("boids", "%s: larger than %zu bytes", a.pos[0], (size_t)CLI_JSON_MAX_SIZE);
        }
        char msg[600];
        const int bad = cli_boids_scene_parse(a.pos[0], text, size, &sc, msg, sizeof msg);
        free(text);
        if (bad) {
            cli_boids_scene_free(&sc);
            return cli_fail("boids", "%s", msg);
        }
    }
    if (count > 0) {
        if (sc.agent_count > 0) {
            cli_boids_scene_free(&sc);
            return cli_usage("boids", "--count conflicts with the scene's \"agents\"");
        }
        sc.count = (size_t)count;
    }
    if (steps >= 0) sc.steps = steps;
    if (seed >= 0) sc.seed = seed;
    if (dt > 0.0f) sc.dt = dt;
    if (CLI_GET(&a, "--2d")) sc.params.planar = true;

    run_state st = {0};
    st.n = sc.agent_count > 0 ? sc.agent_count : sc.count;
    if (sc.params.has_leader && sc.params.leader_index >= st.n) {
        cli_boids_scene_free(&sc);
        return cli_fail("boids", "%s: leader.index: %u is not below the %zu agents", a.pos_count ? a.pos[0] : "scene",
                        sc.params.leader_index, st.n);
    }
    st.p = malloc(st.n * sizeof(ak_vec3));
    st.v = malloc(st.n * sizeof(ak_vec3));
    st.p2 = malloc(st.n * sizeof(ak_vec3));
    st.v2 = malloc(st.n * sizeof(ak_vec3));
    st.w = calloc(st.n, sizeof(ak_vec3));
    st.s = calloc(st.n, 1);
    if (!st.p || !st.v || !st.p2 || !st.v2 || !st.w || !st.s) {
        run_free(&st);
        cli_boids_scene_free(&sc);
        return cli_fail("boids", "out of memory for %zu agents", st.n);
    }
    const ak_boids_params* prm = &sc.params;
    if (sc.agent_count > 0) {
        memcpy(st.p, sc.positions, st.n * sizeof(ak_vec3));
        memcpy(st.v, sc.velocities, st.n * sizeof(ak_vec3));
        memcpy(st.s, sc.agent_species, st.n);
    } else {
        ak_rng r = ak_rng_make((uint64_t)sc.seed);
        const ak_vec3 lo = prm->bounds_min, hi = prm->bounds_max;
        size_t used = 0;
        for (uint32_t k = 1; k < prm->species_count; ++k) {
            size_t c = (size_t)((double)sc.fraction[k] * (double)st.n + 0.5);
            if (c > st.n - used) c = st.n - used;
            for (size_t i = st.n - used - c; i < st.n - used; ++i) st.s[i] = (uint8_t)k;
            used += c;
        }
        for (size_t i = 0; i < st.n; ++i) {
            st.p[i] = ak_vec3_make(ak_rng_range(&r, lo.x, hi.x), prm->planar ? 0.0f : ak_rng_range(&r, lo.y, hi.y),
                                   ak_rng_range(&r, lo.z, hi.z));
            ak_vec3 d = ak_vec3_make(ak_rng_range(&r, -1, 1), prm->planar ? 0.0f : ak_rng_range(&r, -1, 1),
                                     ak_rng_range(&r, -1, 1));
            const float sp = sc.species[st.s[i]].max_speed;
            st.v[i] = ak_vec3_scale(ak_vec3_normalize(d), 0.5f * sp);
        }
    }
    if (prm->planar)
        for (size_t i = 0; i < st.n; ++i) st.v[i].y = 0.0f;

    ak_boids_step_job job = {.params = prm, .positions = {st.p, st.n}, .velocities = {st.v, st.n},
                             .species = {st.s, st.n}, .wander = {st.w, st.n}, .dt = sc.dt,
                             .seed = (uint64_t)sc.seed, .thread_count = (uint32_t)threads,
                             .out_positions = {st.p2, st.n}, .out_velocities = {st.v2, st.n}};
    st.scratch_size = ak_boids_step_scratch_size(&job);
    st.scratch = st.scratch_size ? malloc(st.scratch_size) : NULL;
    job.scratch = (ak_u8_span){st.scratch, st.scratch_size};
    ak_result res = ak_boids_step_validate(&job);
    if (res != AK_OK) {
        run_free(&st);
        cli_boids_scene_free(&sc);
        return cli_fail("boids", "%s: %s", a.pos_count ? a.pos[0] : "scene", ak_result_string(res));
    }

    renderer rd;
    ak_gif_writer* gif = NULL;
    ak_image img = {0};
    bool rendering = out != NULL;
    const bool is_gif = out && cli_has_ext(out, ".gif");
    if (rendering) {
        if (renderer_init(&rd, w, h, &sc, st.n)) {
            renderer_free(&rd);
            run_free(&st);
            cli_boids_scene_free(&sc);
            return cli_fail("boids", "out of memory for rendering");
        }
        img = (ak_image){.pixels = rd.pixels, .width = w, .height = h};
        if (is_gif && ak_gif_writer_create(out, &(ak_gif_desc){.width = w, .height = h, .delay_cs = 4}, NULL, &gif) != AK_OK) {
            renderer_free(&rd);
            run_free(&st);
            cli_boids_scene_free(&sc);
            return cli_fail("boids", "%s: cannot write", out);
        }
    }
    const long every = sc.steps > 150 ? (sc.steps + 149) / 150 : 1;
    const double t0 = cli_now();
    for (long s = 0; s <= sc.steps && res == AK_OK; ++s) {
        if (gif && s % every == 0) {
            res = draw_frame(&rd, &sc, &st, (float)s * sc.dt, &img);
            if (res == AK_OK) res = ak_gif_writer_add_frame(gif, &img);
        }
        if (s == sc.steps) break;
        job.step_index = (uint64_t)s;
        job.positions.ptr = st.p;
        job.velocities.ptr = st.v;
        job.out_positions.ptr = st.p2;
        job.out_velocities.ptr = st.v2;
        if (res == AK_OK) res = ak_boids_step_run(&job);
        ak_vec3* t = st.p;
        st.p = st.p2;
        st.p2 = t;
        t = st.v;
        st.v = st.v2;
        st.v2 = t;
        cli_progress("boids", (size_t)s + 1, (size_t)sc.steps);
    }
    const double elapsed = cli_now() - t0;
    if (res == AK_OK && rendering && !is_gif) {
        res = draw_frame(&rd, &sc, &st, (float)sc.steps * sc.dt, &img);
        if (res == AK_OK) res = ak_png_write(out, &img);
    }
    if (gif) {
        const ak_result fr = ak_gif_writer_finish(gif);
        if (res == AK_OK) res = fr;
    }
    if (rendering) renderer_free(&rd);
    rc = CLI_OK;
    if (res != AK_OK) rc = cli_fail("boids", "%s", ak_result_string(res));
    if (rc == CLI_OK && json) rc = write_json(json, sc.steps, &st);
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
    run_free(&st);
    cli_boids_scene_free(&sc);
    return rc;
}
