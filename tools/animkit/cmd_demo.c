/* animkit demo: the built-in characters at work, no files needed.
 * Writes DIR/demo.gif (walk with a jiggling tail, wave, LBS | DQS | CoR on a bending and
 * twisting cylinder, a squash-and-stretch bouncing ball) and PNG stills. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"

static const char* const usage =
    "usage: animkit demo [-o DIR] [--size WxH]\n"
    "Render the built-in humanoid walking (with a jiggling tail) and waving, the built-in\n"
    "cylinder bending and twisting under LBS | DQS | CoR side by side, and a squash-and-stretch\n"
    "bouncing ball, to DIR/demo.gif (default DIR ./out, frames 640x360), plus PNG stills:\n"
    "demo_walk.png, demo_wave.png, demo_skinning.png, demo_weights.png, demo_curves.png,\n"
    "demo_easing.png. Prints what it wrote and how long it took. Needs no files.\n";

#define FPS 20
#define TAIL_JOINTS 6

typedef struct demo {
    const char* dir;
    int w, h;
    ak_gif_writer* gif;
    ak_image frame;
    size_t frames;
    char path[1024];
} demo;

static const char* out_path(demo* d, const char* name) {
    snprintf(d->path, sizeof d->path, "%s/%s", d->dir, name);
    return d->path;
}

static ak_vec4 rgba(float r, float g, float b, float a) { return ak_vec4_make(r, g, b, a); }

/* ---- a tube along a joint chain, each ring bound rigidly to one joint (the tail) ---------- */

#define TUBE_SEG 12
#define TUBE_RINGS_PER 4
typedef struct tube {
    size_t vertex_count, index_count;
    ak_vec3 rest[TAIL_JOINTS * TUBE_RINGS_PER * TUBE_SEG + 2];
    int bone[TAIL_JOINTS * TUBE_RINGS_PER * TUBE_SEG + 2];
    ak_vec3 pos[TAIL_JOINTS * TUBE_RINGS_PER * TUBE_SEG + 2];
    ak_vec3 nrm[TAIL_JOINTS * TUBE_RINGS_PER * TUBE_SEG + 2];
    uint32_t idx[6 * TAIL_JOINTS * TUBE_RINGS_PER * TUBE_SEG + 6 * TUBE_SEG];
} tube;

/* Tail rest model positions: joints k = 0..TAIL_JOINTS-1 (k = 0 at the pelvis). */
static void tube_build(tube* t, const ak_vec3* joint_pos, float r0, float r1) {
    size_t rings = (TAIL_JOINTS - 1) * TUBE_RINGS_PER + 1, v = 0, n = 0;
    for (size_t ring = 0; ring < rings; ++ring) {
        size_t seg = ring / TUBE_RINGS_PER;
        if (seg >= TAIL_JOINTS - 1) seg = TAIL_JOINTS - 2;
        float u = (float)(ring - seg * TUBE_RINGS_PER) / TUBE_RINGS_PER;
        if (ring == rings - 1) u = 1.0f;
        ak_vec3 a = joint_pos[seg], b = joint_pos[seg + 1];
        ak_vec3 c = ak_vec3_lerp(a, b, u);
        ak_vec3 axis = ak_vec3_normalize(ak_vec3_sub(b, a));
        ak_vec3 e1 = ak_vec3_any_perpendicular(axis), e2 = ak_vec3_cross(axis, e1);
        float rad = ak_lerpf(r0, r1, (float)ring / (float)(rings - 1));
        for (int k = 0; k < TUBE_SEG; ++k) {
            float ang = AK_TWO_PI * (float)k / TUBE_SEG;
            t->rest[v] = ak_vec3_add(c, ak_vec3_add(ak_vec3_scale(e1, rad * cosf(ang)), ak_vec3_scale(e2, rad * sinf(ang))));
            t->bone[v] = (int)(u < 0.5f || ring == rings - 1 ? seg + (ring == rings - 1) : seg + 1);
            if (t->bone[v] > TAIL_JOINTS - 1) t->bone[v] = TAIL_JOINTS - 1;
            ++v;
        }
    }
    t->rest[v] = joint_pos[TAIL_JOINTS - 1];
    t->bone[v] = TAIL_JOINTS - 1;
    size_t tip = v++;
    for (size_t ring = 0; ring + 1 < rings; ++ring)
        for (uint32_t k = 0; k < TUBE_SEG; ++k) {
            uint32_t a = (uint32_t)(ring * TUBE_SEG + k), b = (uint32_t)(ring * TUBE_SEG + (k + 1) % TUBE_SEG);
            uint32_t c = a + TUBE_SEG, d = b + TUBE_SEG;
            uint32_t tri[6] = {a, c, b, b, c, d};
            memcpy(&t->idx[n], tri, sizeof tri);
            n += 6;
        }
    for (uint32_t k = 0; k < TUBE_SEG; ++k) {
        uint32_t a = (uint32_t)((rings - 1) * TUBE_SEG + k), b = (uint32_t)((rings - 1) * TUBE_SEG + (k + 1) % TUBE_SEG);
        t->idx[n++] = a;
        t->idx[n++] = (uint32_t)tip;
        t->idx[n++] = b;
    }
    t->vertex_count = v;
    t->index_count = n;
}

/* ---- a UV sphere for the ball ------------------------------------------------------------- */

#define SPH_U 32
#define SPH_V 16
typedef struct sphere {
    ak_vec3 pos[(SPH_U + 1) * (SPH_V + 1)];
    ak_vec3 nrm[(SPH_U + 1) * (SPH_V + 1)];
    ak_vec3 out_pos[(SPH_U + 1) * (SPH_V + 1)];
    ak_vec3 out_nrm[(SPH_U + 1) * (SPH_V + 1)];
    uint32_t idx[SPH_U * SPH_V * 6];
} sphere;

static void sphere_build(sphere* s) {
    size_t v = 0, n = 0;
    for (int j = 0; j <= SPH_V; ++j)
        for (int i = 0; i <= SPH_U; ++i) {
            float th = AK_PI * (float)j / SPH_V, ph = AK_TWO_PI * (float)i / SPH_U;
            s->pos[v] = s->nrm[v] = ak_vec3_make(sinf(th) * cosf(ph), cosf(th), -sinf(th) * sinf(ph));
            ++v;
        }
    for (int j = 0; j < SPH_V; ++j)
        for (int i = 0; i < SPH_U; ++i) {
            uint32_t a = (uint32_t)(j * (SPH_U + 1) + i), b = a + 1, c = a + SPH_U + 1, d = c + 1;
            uint32_t tri[6] = {a, c, b, b, c, d};
            memcpy(&s->idx[n], tri, sizeof tri);
            n += 6;
        }
}

/* ---- frames ------------------------------------------------------------------------------- */

static ak_result add_frame(demo* d, const ak_image* img) {
    ++d->frames;
    return ak_gif_writer_add_frame(d->gif, img);
}

/* Centre src on a dark background in d->frame and add it. */
static ak_result add_letterboxed(demo* d, const ak_image* src) {
    ak_image_fill(&d->frame, rgba(0.14f, 0.15f, 0.18f, 1));
    ak_image_blit(&d->frame, (d->w - src->width) / 2, (d->h - src->height) / 2, src);
    return add_frame(d, &d->frame);
}

static int fail(const char* what, ak_result r) { return cli_fail("demo", "%s: %s", what, ak_result_string(r)); }

/* Humanoid: walk (two loops, with a jiggling tail) then wave. */
static int humanoid_part(demo* d, double* t_used) {
    double t0 = cli_now();
    ak_scene* s = NULL;
    int rc = cli_load_scene("demo", "builtin:humanoid", &s);
    if (rc) return rc;
    cli_poser p;
    cli_frame f;
    tube* tail = calloc(1, sizeof(tube));
    memset(&f, 0, sizeof f);
    if (!tail || cli_poser_init(&p, s)) {
        free(tail);
        ak_scene_destroy(s);
        return cli_fail("demo", "out of memory");
    }
    int walk = ak_scene_find_clip(s, "walk"), wave = ak_scene_find_clip(s, "wave");
    int pelvis = ak_skeleton_find_joint(s->skeleton, "pelvis");
    /* framing over both clips */
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    for (int c = 0; c < 2; ++c) {
        int clip = c ? wave : walk;
        float dur = ak_clip_duration(s->clips[clip]);
        for (float t = 0; t <= dur; t += 0.1f) {
            cli_poser_pose(&p, clip, t, false, CLI_LBS);
            cli_bounds_add_pose(&p, &lo, &hi);
        }
    }
    lo.z -= 0.35f; /* room for the tail */
    if (cli_frame_init(&f, s, d->w, d->h, lo, hi, 1.15f)) {
        rc = cli_fail("demo", "out of memory");
        goto done;
    }
    /* the tail: a chain hanging back from the pelvis, jiggled by the walk */
    cli_poser_pose(&p, -1, 0, true, CLI_LBS);
    ak_mat4 pelvis_rest = p.world[pelvis];
    ak_vec3 base = ak_vec3_add(ak_mat4_get_translation(pelvis_rest), ak_vec3_make(0, -0.05f, -0.12f));
    ak_vec3 tail_rest[TAIL_JOINTS];
    for (int k = 0; k < TAIL_JOINTS; ++k)
        tail_rest[k] = ak_vec3_add(base, ak_vec3_make(0, 0.06f * (float)k - 0.012f * (float)(k * k), -0.065f * (float)k));
    tube_build(tail, tail_rest, 0.045f, 0.015f);
    int32_t parents[TAIL_JOINTS + 1];
    ak_mat4 model[TAIL_JOINTS + 1], out_model[TAIL_JOINTS + 1], local[TAIL_JOINTS + 1], rest_inv[TAIL_JOINTS + 1];
    ak_jiggle_joint jj[TAIL_JOINTS - 1];
    ak_jiggle_state js[TAIL_JOINTS - 1];
    memset(js, 0, sizeof js);
    parents[0] = -1;
    ak_mat4 prev = pelvis_rest;
    for (int k = 0; k < TAIL_JOINTS; ++k) {
        parents[k + 1] = (int32_t)k;
        ak_mat4 m = ak_mat4_translation(tail_rest[k]);
        local[k + 1] = ak_mat4_mul(ak_mat4_inverse_affine(prev), m);
        rest_inv[k + 1] = ak_mat4_inverse_affine(m);
        prev = m;
        if (k < TAIL_JOINTS - 1) jj[k] = (ak_jiggle_joint){.joint = k + 1, .tip = ak_vec3_sub(tail_rest[k + 1], tail_rest[k])};
    }
    ak_jiggle_job job = {
        .params = {.stiffness = 60.0f, .damping = 7.0f, .gravity = {0, -2.0f, 0}},
        .parents = {parents, TAIL_JOINTS + 1},
        .joints = jj,
        .joint_count = TAIL_JOINTS - 1,
        .states = {js, TAIL_JOINTS - 1},
        .model = {model, TAIL_JOINTS + 1},
        .out_model = {out_model, TAIL_JOINTS + 1},
    };
    ak_raster_mesh tail_mesh = {
        .positions = {tail->pos, tail->vertex_count},
        .normals = {tail->nrm, tail->vertex_count},
        .indices = {tail->idx, tail->index_count},
        .material = {.color = rgba(0.90f, 0.50f, 0.15f, 1)},
    };
    ak_image still = {0};
    if (cli_image_alloc(&still, d->w, d->h)) {
        rc = cli_fail("demo", "out of memory");
        goto done;
    }
    const int walk_frames = 2 * FPS, wave_frames = (int)(ak_clip_duration(s->clips[wave]) * FPS);
    float walk_dur = ak_clip_duration(s->clips[walk]);
    for (int i = 0; i < walk_frames + wave_frames && rc == CLI_OK; ++i) {
        bool walking = i < walk_frames;
        float t = walking ? ak_time_wrap((float)i / FPS, walk_dur, AK_WRAP_LOOP) : (float)(i - walk_frames) / FPS;
        ak_result r = cli_poser_pose(&p, walking ? walk : wave, t, false, CLI_LBS);
        /* tail: animated model matrices follow the pelvis, then jiggle */
        model[0] = p.world[pelvis];
        for (int k = 1; k <= TAIL_JOINTS; ++k) model[k] = ak_mat4_mul(model[parents[k]], local[k]);
        job.dt = i == 0 ? 0.0f : 1.0f / FPS;
        if (r == AK_OK) r = ak_jiggle_run(&job);
        for (size_t v = 0; r == AK_OK && v < tail->vertex_count; ++v) {
            int b = tail->bone[v] + 1;
            ak_mat4 skin = ak_mat4_mul(out_model[b], rest_inv[b]);
            tail->pos[v] = ak_mat4_transform_point(skin, tail->rest[v]);
        }
        if (r == AK_OK)
            ak_normals_compute((ak_vec3_cspan){tail->pos, tail->vertex_count}, (ak_u32_cspan){tail->idx, tail->index_count},
                               (ak_vec3_span){tail->nrm, tail->vertex_count});
        char title[96];
        snprintf(title, sizeof title, "%s  t=%.2fs", walking ? "walk + jiggling tail" : "wave", (double)t);
        cli_draw_opts o = {.title = title, .extra = &tail_mesh, .extra_count = 1};
        if (r == AK_OK) r = cli_frame_draw(&f, &p, &o, &d->frame);
        if (r == AK_OK) r = add_frame(d, &d->frame);
        if (r == AK_OK && (i == 6 || i == walk_frames + 22))
            r = ak_png_write(out_path(d, i == 6 ? "demo_walk.png" : "demo_wave.png"), &d->frame);
        if (r != AK_OK) rc = fail("humanoid frames", r);
        cli_progress("humanoid", (size_t)i + 1, (size_t)(walk_frames + wave_frames));
    }
    /* weights heatmap of the left hip (bone heat weights are the builtin's own procedural ones) */
    if (rc == CLI_OK) {
        ak_vec4* colors[1] = {NULL};
        int found = 0;
        cli_poser_pose(&p, -1, 0, true, CLI_LBS);
        if (cli_weights_colors(s, "left_hip", colors, &found) == CLI_OK && found) {
            cli_draw_opts o = {.colors = colors, .title = "skin weights of left_hip (the thigh bone)"};
            if (cli_frame_draw(&f, &p, &o, &still) != AK_OK || ak_png_write(out_path(d, "demo_weights.png"), &still) != AK_OK)
                rc = cli_fail("demo", "%s: cannot write", d->path);
        }
        free(colors[0]);
    }
    free(still.pixels);
done:
    free(tail);
    cli_frame_free(&f);
    cli_poser_free(&p);
    ak_scene_destroy(s);
    *t_used = cli_now() - t0;
    return rc;
}

/* Cylinder bending and twisting, LBS | DQS | CoR side by side. */
static int cylinder_part(demo* d, double* t_used) {
    double t0 = cli_now();
    ak_scene* s = NULL;
    int rc = cli_load_scene("demo", "builtin:cylinder", &s);
    if (rc) return rc;
    cli_poser p;
    cli_frame f;
    memset(&f, 0, sizeof f);
    ak_image panel[3] = {{0}}, composed = {0};
    if (cli_poser_init(&p, s)) {
        ak_scene_destroy(s);
        return cli_fail("demo", "out of memory");
    }
    int clip = ak_scene_find_clip(s, "bend_twist");
    float dur = ak_clip_duration(s->clips[clip]);
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    for (float t = 0; t <= dur + 1e-4f; t += 0.1f) {
        cli_poser_pose(&p, clip, t, false, CLI_LBS);
        cli_bounds_add_pose(&p, &lo, &hi);
    }
    ak_view_panels_desc pd = {.title = "bend + twist", .label_scale = 2};
    int gap_w, gap_h, pw = (d->w - 24) / 3, ph = d->h - 60;
    if (pw < 8) pw = 8;
    if (ph < 8) ph = 8;
    ak_view_panels_size(&pd, 3, pw, ph, &gap_w, &gap_h);
    while ((gap_w > d->w || gap_h > d->h) && ph > 8 && pw > 8) {
        --ph, --pw;
        ak_view_panels_size(&pd, 3, pw, ph, &gap_w, &gap_h);
    }
    if (cli_frame_init(&f, s, pw, ph, lo, hi, 0.6f) || cli_image_alloc(&composed, gap_w, gap_h)) {
        rc = cli_fail("demo", "out of memory");
        goto done;
    }
    static const char* const labels[3] = {"LBS", "DQS", "CoR"};
    ak_view_panel panels[3];
    for (int k = 0; k < 3; ++k) {
        if (cli_image_alloc(&panel[k], pw, ph)) {
            rc = cli_fail("demo", "out of memory");
            goto done;
        }
        panels[k] = (ak_view_panel){&panel[k], labels[k]};
    }
    int frames = (int)(dur * FPS) + 1, hold = FPS / 2;
    for (int i = 0; i < frames + hold && rc == CLI_OK; ++i) {
        float t = i < frames ? (float)i / FPS : dur;
        ak_result r = AK_OK;
        for (int k = 0; k < 3 && r == AK_OK; ++k) {
            char title[32];
            snprintf(title, sizeof title, "t=%.2fs", (double)t);
            cli_draw_opts o = {.title = title};
            r = cli_poser_pose(&p, clip, t, false, (cli_method)k);
            if (r == AK_OK) r = cli_frame_draw(&f, &p, &o, &panel[k]);
        }
        if (r == AK_OK) r = ak_view_panels_compose(&pd, panels, 3, &composed);
        if (r == AK_OK) r = add_letterboxed(d, &composed);
        if (r == AK_OK && i == frames + hold - 1) r = ak_png_write(out_path(d, "demo_skinning.png"), &composed);
        if (r != AK_OK) rc = fail("cylinder frames", r);
        cli_progress("cylinder", (size_t)i + 1, (size_t)(frames + hold));
    }
done:
    for (int k = 0; k < 3; ++k) free(panel[k].pixels);
    free(composed.pixels);
    cli_frame_free(&f);
    cli_poser_free(&p);
    ak_scene_destroy(s);
    *t_used = cli_now() - t0;
    return rc;
}

/* A bouncing ball that squashes on contact and stretches in flight. */
static int ball_part(demo* d, double* t_used) {
    double t0 = cli_now();
    sphere* sp = calloc(1, sizeof(sphere));
    cli_frame f;
    memset(&f, 0, sizeof f);
    int rc = CLI_OK;
    if (!sp) return cli_fail("demo", "out of memory");
    sphere_build(sp);
    ak_bounce_desc bd = {.height = 1.2f, .radius = 0.25f, .forward_speed = 0.6f, .start = {-1.0f, 0, 0}};
    float period = ak_bounce_period(&bd);
    int frames = (int)(2.0f * period * FPS);
    ak_vec3 lo = ak_vec3_make(-1.3f, 0, -0.4f), hi = ak_vec3_make(-1.0f + 0.6f * 2.0f * period + 0.3f, 1.2f + 0.6f, 0.4f);
    if (cli_frame_init(&f, NULL, d->w, d->h, lo, hi, 0.25f)) {
        free(sp);
        return cli_fail("demo", "out of memory");
    }
    ak_raster_mesh ball = {
        .positions = {sp->out_pos, (SPH_U + 1) * (SPH_V + 1)},
        .normals = {sp->out_nrm, (SPH_U + 1) * (SPH_V + 1)},
        .indices = {sp->idx, SPH_U * SPH_V * 6},
        .material = {.color = rgba(0.85f, 0.22f, 0.18f, 1), .specular = 0.5f, .shininess = 48},
    };
    for (int i = 0; i < frames && rc == CLI_OK; ++i) {
        ak_bounce_state st = ak_bounce_sample(&bd, (float)i / FPS);
        ak_mat3 nm = ak_mat4_normal_matrix(st.model);
        for (size_t v = 0; v < (SPH_U + 1) * (SPH_V + 1); ++v) {
            sp->out_pos[v] = ak_mat4_transform_point(st.model, sp->pos[v]);
            sp->out_nrm[v] = ak_vec3_normalize(ak_mat3_mul_vec3(nm, sp->nrm[v]));
        }
        char title[96];
        snprintf(title, sizeof title, "squash & stretch  s=%.2f", (double)st.stretch);
        cli_draw_opts o = {.title = title, .extra = &ball, .extra_count = 1};
        ak_result r = cli_frame_draw(&f, NULL, &o, &d->frame);
        if (r == AK_OK) r = add_frame(d, &d->frame);
        if (r != AK_OK) rc = fail("ball frames", r);
        cli_progress("ball", (size_t)i + 1, (size_t)frames);
    }
    cli_frame_free(&f);
    free(sp);
    *t_used = cli_now() - t0;
    return rc;
}

/* The easing functions (slow in, slow out) as a chart. */
static int easing_png(demo* d) {
    enum { N = 101 };
    static const ak_ease_kind kinds[] = {AK_EASE_LINEAR, AK_EASE_SMOOTHSTEP, AK_EASE_SINE_IN_OUT, AK_EASE_CUBIC_IN_OUT,
                                         AK_EASE_QUAD_IN, AK_EASE_EXPO_OUT};
    static const char* const names[] = {"linear", "smoothstep", "sine in-out", "cubic in-out", "quad in", "expo out"};
    float x[N], y[6][N];
    ak_view_series series[6];
    for (int i = 0; i < N; ++i) x[i] = (float)i / (N - 1);
    for (int k = 0; k < 6; ++k) {
        for (int i = 0; i < N; ++i) y[k][i] = ak_ease(kinds[k], x[i]);
        series[k] = (ak_view_series){.x = {x, N}, .y = {y[k], N}, .label = names[k]};
    }
    ak_view_plot plot = {.series = series, .series_count = 6, .title = "easing: slow in, slow out",
                         .x_label = "u = t / duration"};
    ak_image img = {0};
    int rc = CLI_OK;
    if (cli_image_alloc(&img, 640, 420) || ak_view_plot_draw(&plot, &img) != AK_OK ||
        ak_png_write(out_path(d, "demo_easing.png"), &img) != AK_OK)
        rc = cli_fail("demo", "%s: cannot write", d->path);
    free(img.pixels);
    return rc;
}

int cmd_demo(int argc, char** argv) {
    static const cli_opt opts[] = {{"--output", "-o", true}, {"--size", NULL, true}};
    cli_args a;
    int rc = cli_parse("demo", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count) return cli_usage("demo", "unexpected argument '%s'", a.pos[0]);
    demo d = {.dir = CLI_GET(&a, "--output") ? CLI_GET(&a, "--output") : "out", .w = 640, .h = 360};
    if (CLI_GET(&a, "--size") && (!cli_parse_size(CLI_GET(&a, "--size"), &d.w, &d.h) || d.w < 96 || d.h < 64))
        return cli_usage("demo", "--size '%s' is not WxH of at least 96x64", CLI_GET(&a, "--size"));
    if (!cli_mkdir_p(d.dir)) return cli_fail("demo", "%s: cannot create the directory", d.dir);
    double t0 = cli_now(), th = 0, tc = 0, tb = 0;
    if (cli_image_alloc(&d.frame, d.w, d.h)) return cli_fail("demo", "out of memory");
    ak_result r = ak_gif_writer_create(out_path(&d, "demo.gif"),
                                       &(ak_gif_desc){.width = d.w, .height = d.h, .delay_cs = 100 / FPS}, NULL, &d.gif);
    if (r != AK_OK) {
        free(d.frame.pixels);
        return cli_fail("demo", "%s: cannot create the file", d.path);
    }
    rc = humanoid_part(&d, &th);
    if (!rc) rc = cylinder_part(&d, &tc);
    if (!rc) rc = ball_part(&d, &tb);
    if (rc) ak_gif_writer_discard(d.gif); /* a failed demo leaves no partial GIF */
    r = rc ? AK_OK : ak_gif_writer_finish(d.gif);
    if (!rc && r != AK_OK) rc = fail(out_path(&d, "demo.gif"), r);
    free(d.frame.pixels);
    if (!rc) rc = easing_png(&d);
    if (!rc) {
        char a0[] = "builtin:humanoid", a1[] = "--clip", a2[] = "walk", a3[] = "--joint", a4[] = "left_knee", a5[] = "-o";
        char a6[1024];
        snprintf(a6, sizeof a6, "%s/demo_curves.png", d.dir);
        char* cv[] = {a0, a1, a2, a3, a4, a5, a6};
        rc = cli_curves_run(7, cv, true);
    }
    if (rc) return rc;
    printf("animkit demo: wrote to %s/\n", d.dir);
    printf("  demo.gif          %zu frames %dx%d: walk + jiggling tail, wave (%.2f s); LBS|DQS|CoR cylinder (%.2f s); "
           "bouncing ball (%.2f s)\n",
           d.frames, d.w, d.h, th, tc, tb);
    printf("  demo_walk.png demo_wave.png demo_skinning.png demo_weights.png demo_curves.png demo_easing.png\n");
    printf("  total %.2f s (image formats: %s)\n", cli_now() - t0, ak_image_formats_string());
    return CLI_OK;
}
