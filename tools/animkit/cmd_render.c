/* animkit render: a posed or animated model to PNG or GIF, optionally LBS | DQS | CoR side by side. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"

static const char* const usage =
    "usage: animkit render FILE|builtin:NAME [--clip C] [--time T | --frames A:B:STEP |\n"
    "                      --fps F [--duration D]] [--method lbs|dqs|cor|implicit|soft|all] [--size WxH]\n"
    "                      [--camera YAW,PITCH[,DIST]] [--follow] [--fov DEG] [--mesh NAME]...\n"
    "                      [--skeleton] [--weights BONE] -o OUT.png|OUT.gif\n"
    "Render the model posed by clip C (default the first) with an orbit camera framing the\n"
    "whole motion. Times: --time T (one frame), --frames A:B:STEP (A to B inclusive, in\n"
    "seconds), --fps F (frames at 0, 1/F, ... through the clip) or --fps F --duration D (frames\n"
    "at 0, 1/F, ... before D). A GIF without times plays the whole clip at 24 fps, or at 12 fps\n"
    "when the clip is longer than 10 s (it says which); a PNG without times shows t = 0. GIF\n"
    "frame delays are whole 1/100 s: they alternate (24 fps: 4,4,5,4,4,4) so that the average\n"
    "matches the rate. Several frames into a PNG write OUT_0000.png, OUT_0001.png, ...\n"
    "  --method all   LBS | DQS | CoR | implicit | soft in labelled panels side by side (soft:\n"
    "                 the flesh simulated through the frames from time 0, see 'animkit skin --help')\n"
    "  --size WxH     output size of one panel (default 640x480); the whole image, panels\n"
    "                 included, is at most 8192x8192\n"
    "  --camera YAW,PITCH[,DIST]  degrees about +Y (0: from +Z, 90: from +X) and above the\n"
    "                 horizon (-85..85), and the distance from the framed centre in scene units\n"
    "                 (default: just far enough to frame it); default 31.5,12.6\n"
    "  --follow       frame the character's size, not its whole path, and move the camera with\n"
    "                 the root joint (a walk stays framed); the ground stays put\n"
    "  --fov DEG      vertical field of view (default 40)\n"
    "  --mesh NAME    draw only the meshes named NAME (repeatable); an OBJ from MakeHuman hides\n"
    "                 its helper-* and joint-* meshes unless named\n"
    "  --skeleton     overlay the skeleton\n"
    "  --weights BONE colour the meshes by BONE's skin weights (blue 0 -> red 1)\n"
    "An OBJ file is geometry only (no rig is read, e.g. a MakeHuman .mhskel beside it); meshes\n"
    "without normals in the file are shaded smooth, vertices at the same position sharing one\n"
    "normal. Formats this build writes: png gif.\n";

#define MAX_SIDE 8192
#define LONG_CLIP 10.0f /* seconds: GIFs of longer clips default to 12 fps */

typedef struct frame_times {
    float* t;
    size_t count;
    float step;      /* seconds between frames (the GIF rate is 1 / step) */
    bool subsampled; /* a long clip's GIF got the lower default rate */
} frame_times;

static int parse_times(cli_args* a, const cli_opt* opts, size_t nopts, bool gif, float clip_duration, frame_times* out) {
    const char* time = cli_get(a, opts, nopts, "--time");
    const char* frames = cli_get(a, opts, nopts, "--frames");
    const char* fps = cli_get(a, opts, nopts, "--fps");
    const char* dur = cli_get(a, opts, nopts, "--duration");
    int given = (time != NULL) + (frames != NULL) + (fps != NULL || dur != NULL);
    if (given > 1) return cli_usage("render", "use one of --time, --frames, or --fps [with --duration]");
    float t0 = 0, t1 = 0, step = 0;
    out->subsampled = false;
    if (time) {
        if (!cli_parse_float(time, &t0)) return cli_usage("render", "--time '%s' is not a number", time);
        t1 = t0;
        step = 1;
    } else if (frames) {
        char buf[128];
        if (strlen(frames) >= sizeof buf) return cli_usage("render", "--frames '%s' is not A:B:STEP", frames);
        strcpy(buf, frames);
        char* c1 = strchr(buf, ':');
        char* c2 = c1 ? strchr(c1 + 1, ':') : NULL;
        if (!c1 || !c2) return cli_usage("render", "--frames '%s' is not A:B:STEP", frames);
        *c1 = *c2 = '\0';
        if (!cli_parse_float(buf, &t0) || !cli_parse_float(c1 + 1, &t1) || !cli_parse_float(c2 + 1, &step) ||
            !(step > 0) || t1 < t0)
            return cli_usage("render", "--frames '%s' needs numbers A <= B and STEP > 0", frames);
    } else if (fps || dur) {
        float f = 0, d = 0;
        if (!fps) return cli_usage("render", "--duration needs --fps");
        if (!cli_parse_float(fps, &f) || !(f > 0) || f > 1000) return cli_usage("render", "--fps '%s' is not a rate in (0, 1000]", fps);
        if (dur && (!cli_parse_float(dur, &d) || !(d > 0))) return cli_usage("render", "--duration '%s' is not a number > 0", dur);
        t0 = 0;
        step = 1.0f / f;
        if (dur) t1 = d - 0.5f * step;
        else t1 = clip_duration; /* the whole clip, its last instant included when it falls on a frame */
    } else if (gif && clip_duration > 0) {
        out->subsampled = clip_duration > LONG_CLIP;
        step = 1.0f / (out->subsampled ? 12.0f : 24.0f);
        t1 = clip_duration;
    } else {
        step = 1;
    }
    /* a last frame within 1e-4 steps of B counts (float steps such as 1/12 do not divide exactly) */
    double count = floor((double)(t1 - t0) / (double)step + 1e-4) + 1.0;
    if (count > 10000) return cli_usage("render", "%.0f frames is too many (at most 10000)", count);
    out->count = (size_t)count;
    out->step = step;
    out->t = calloc(out->count, sizeof(float));
    if (!out->t) return cli_fail("render", "out of memory");
    for (size_t i = 0; i < out->count; ++i) out->t[i] = t0 + (float)((double)i * (double)step);
    return CLI_OK;
}

/* "YAW,PITCH[,DIST]" in degrees (and scene units) */
static bool parse_camera(const char* s, cli_camera* cam) {
    char buf[128];
    if (!s || strlen(s) >= sizeof buf) return false;
    strcpy(buf, s);
    float v[3] = {0, 0, 0};
    int n = 0;
    /* split by hand: strtok would read "0,,10" as YAW 0, PITCH 10 */
    for (char* tok = buf;; ++n) {
        char* comma = strchr(tok, ',');
        if (comma) *comma = '\0';
        if (n == 3 || !cli_parse_float(tok, &v[n])) return false;
        if (!comma) break;
        tok = comma + 1;
    }
    ++n;
    if (n < 2 || v[1] < -85.0f || v[1] > 85.0f || (n == 3 && !(v[2] > 0.0f && v[2] <= 1e9f))) return false;
    cam->has_angles = true;
    cam->yaw = v[0];
    cam->pitch = v[1];
    cam->distance = n == 3 ? v[2] : 0.0f;
    return true;
}

/* MakeHuman's helper geometry in its base OBJ (hidden by default). */
static bool mh_helper(const char* name) { return strncmp(name, "helper-", 7) == 0 || strncmp(name, "joint-", 6) == 0; }

/* The root joint's world position (the first skin joint; no joints -> NaN). */
static ak_vec3 root_position(const cli_poser* p) {
    const ak_scene* s = p->scene;
    for (size_t j = 0; j < p->joint_count; ++j)
        if (!s->is_joint || s->is_joint[j]) return ak_mat4_get_translation(p->world[j]);
    return ak_vec3_splat(NAN);
}

/* Render frame times into images (one panel per method) and hand each composed frame to sink. */
int cmd_render(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--clip", "-c", true},     {"--time", "-t", true},   {"--frames", NULL, true},  {"--fps", NULL, true},
        {"--duration", NULL, true}, {"--method", "-m", true}, {"--size", NULL, true},    {"--skeleton", NULL, false},
        {"--weights", NULL, true},  {"--output", "-o", true}, {"--camera", NULL, true},  {"--follow", NULL, false},
        {"--fov", NULL, true},      {"--mesh", NULL, true},
    };
    const size_t nopts = sizeof opts / sizeof opts[0];
    cli_args a;
    int rc = cli_parse("render", argc, argv, opts, nopts, &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 1) return cli_usage("render", "expected one FILE or builtin:NAME");
    const char* out = CLI_GET(&a, "--output");
    if (!out) return cli_usage("render", "missing -o OUT.png|OUT.gif");
    bool gif = cli_has_ext(out, ".gif");
    if (!gif && !cli_has_ext(out, ".png")) return cli_usage("render", "output '%s' must end in .png or .gif", out);
    int w = 640, h = 480;
    if (CLI_GET(&a, "--size") && !cli_parse_size(CLI_GET(&a, "--size"), &w, &h))
        return cli_usage("render", "--size '%s' is not WxH with 8..8192 pixels each", CLI_GET(&a, "--size"));
    cli_method methods[5] = {CLI_LBS, CLI_DQS, CLI_COR, CLI_IMPLICIT, CLI_SOFT};
    size_t method_count = 1;
    const char* ms = CLI_GET(&a, "--method");
    if (ms && strcmp(ms, "all") == 0) method_count = 5;
    else if (ms && !cli_method_parse(ms, &methods[0]))
        return cli_usage("render", "--method must be lbs, dqs, cor, implicit, soft or all, not '%s'", ms);
    cli_camera cam = {0};
    if (CLI_GET(&a, "--camera") && !parse_camera(CLI_GET(&a, "--camera"), &cam))
        return cli_usage("render", "--camera '%s' is not YAW,PITCH[,DIST] (degrees, pitch in -85..85, distance in (0, 1e9])",
                         CLI_GET(&a, "--camera"));
    if (CLI_GET(&a, "--fov") && (!cli_parse_float(CLI_GET(&a, "--fov"), &cam.fov) || !(cam.fov >= 1.0f && cam.fov <= 170.0f)))
        return cli_usage("render", "--fov '%s' is not an angle in 1..170 degrees", CLI_GET(&a, "--fov"));
    bool follow = CLI_GET(&a, "--follow") != NULL;
    const char* mesh_names[CLI_MAX_ALL];
    size_t mesh_name_count = cli_get_all(&a, opts, nopts, "--mesh", mesh_names, CLI_MAX_ALL);
    /* the size limit holds for the whole image, panels and labels included */
    static const char* const labels[5] = {"LBS", "DQS", "CoR", "implicit", "soft"};
    ak_view_panels_desc pd = {.title = "title"};
    int cw = w, ch = h;
    if (method_count > 1) ak_view_panels_size(&pd, method_count, w, h, &cw, &ch);
    if (cw > MAX_SIDE || ch > MAX_SIDE) {
        int mw = w, mh = h, big_w = cw, big_h = ch;
        while (mw > 8 && mh > 8 && (cw > MAX_SIDE || ch > MAX_SIDE)) {
            mw = mw * 15 / 16, mh = mh * 15 / 16;
            ak_view_panels_size(&pd, method_count, mw, mh, &cw, &ch);
        }
        return cli_usage("render", "--method all with --size %dx%d makes a %dx%d image, above the %dx%d limit (try --size %dx%d)",
                         w, h, big_w, big_h, MAX_SIDE, MAX_SIDE, mw, mh);
    }
    /* check the time flags before loading */
    {
        frame_times probe = {0};
        if ((rc = parse_times(&a, opts, nopts, gif, 1.0f, &probe))) return rc;
        free(probe.t);
    }

    ak_scene* s = NULL;
    if ((rc = cli_load_scene("render", a.pos[0], &s))) return rc;
    cli_poser p;
    cli_frame f;
    frame_times ft = {0};
    ak_image panel[5] = {{0}}, composed = {0};
    ak_vec4** colors = NULL;
    bool* hidden = NULL;
    ak_vec3 *frame_lo = NULL, *frame_hi = NULL, *roots = NULL;
    ak_gif_writer* gw = NULL;
    memset(&p, 0, sizeof p);
    memset(&f, 0, sizeof f);
    int clip = -1;
    if (CLI_GET(&a, "--clip")) {
        clip = ak_scene_find_clip(s, CLI_GET(&a, "--clip"));
        if (clip < 0) {
            rc = cli_no_clip("render", a.pos[0], CLI_GET(&a, "--clip"), s);
            goto done;
        }
    } else if (s->clip_count) {
        clip = 0;
    }
    if (!(colors = calloc(s->mesh_count + 1, sizeof(ak_vec4*))) || !(hidden = calloc(s->mesh_count + 1, sizeof(bool)))) {
        rc = cli_fail("render", "out of memory");
        goto done;
    }
    /* meshes to draw: --mesh names, else all but an OBJ's MakeHuman helpers */
    bool obj = cli_has_ext(a.pos[0], ".obj");
    if (mesh_name_count) {
        for (size_t m = 0; m < s->mesh_count; ++m) hidden[m] = true;
        for (size_t k = 0; k < mesh_name_count; ++k) {
            bool found = false;
            for (size_t m = 0; m < s->mesh_count; ++m)
                if (s->meshes[m].mesh && strcmp(s->meshes[m].mesh->name, mesh_names[k]) == 0) hidden[m] = false, found = true;
            if (!found) {
                rc = cli_fail("render", "%s: no mesh named '%s' (%zu mesh%s; 'animkit info' lists them)", a.pos[0],
                              mesh_names[k], s->mesh_count, s->mesh_count == 1 ? "" : "es");
                goto done;
            }
        }
    } else if (obj) {
        size_t helpers = 0;
        for (size_t m = 0; m < s->mesh_count; ++m) helpers += s->meshes[m].mesh && mh_helper(s->meshes[m].mesh->name);
        if (helpers && helpers < s->mesh_count) {
            for (size_t m = 0; m < s->mesh_count; ++m) hidden[m] = s->meshes[m].mesh && mh_helper(s->meshes[m].mesh->name);
            fprintf(stderr, "note: %s: %zu MakeHuman helper mesh%s (helper-*, joint-*) hidden; --mesh NAME picks meshes\n",
                    a.pos[0], helpers, helpers == 1 ? "" : "es");
        }
    }
    if (obj) cli_obj_rig_note("render", a.pos[0]);
    bool skinned = false;
    for (size_t m = 0; m < s->mesh_count; ++m) skinned = skinned || (s->meshes[m].skin >= 0 && s->meshes[m].mesh->influence_count);
    const char* bone = CLI_GET(&a, "--weights");
    if (bone) {
        int found = 0;
        if ((rc = cli_weights_colors(s, bone, colors, &found))) goto done;
        if (!found) {
            rc = cli_fail("render", "%s: no skinned mesh is weighted to a joint named '%s'", a.pos[0], bone);
            goto done;
        }
    }
    float clip_duration = clip >= 0 ? ak_clip_duration(s->clips[clip]) : 0.0f;
    if ((rc = parse_times(&a, opts, nopts, gif, clip_duration, &ft))) goto done;
    if (clip >= 0 && CLI_GET(&a, "--time") && ft.count == 1) cli_time_note("render", ft.t[0], s->clips[clip]);
    if (ft.subsampled)
        fprintf(stderr, "note: %.2f s clip: 12 fps (%zu frames) to keep the GIF small (24 fps up to %.0f s; --fps F to choose)\n",
                (double)clip_duration, ft.count, (double)LONG_CLIP);
    if (cli_poser_init(&p, s)) {
        rc = cli_fail("render", "out of memory");
        goto done;
    }
    p.weld_normals = obj;
    frame_lo = calloc(ft.count, sizeof(ak_vec3));
    frame_hi = calloc(ft.count, sizeof(ak_vec3));
    roots = calloc(ft.count, sizeof(ak_vec3));
    if (!frame_lo || !frame_hi || !roots) {
        rc = cli_fail("render", "out of memory");
        goto done;
    }
    /* frame the camera on every frame of the motion (LBS; other methods stay close) */
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    for (size_t i = 0; i < ft.count; ++i) {
        ak_result r = cli_poser_pose(&p, clip, ft.t[i], false, CLI_LBS);
        if (r != AK_OK) {
            rc = cli_fail("render", "%s: cannot pose at t=%g: %s", a.pos[0], (double)ft.t[i], ak_result_string(r));
            goto done;
        }
        frame_lo[i] = ak_vec3_splat(INFINITY), frame_hi[i] = ak_vec3_splat(-INFINITY);
        cli_bounds_add_visible(&p, hidden, &frame_lo[i], &frame_hi[i]);
        lo = ak_vec3_min(lo, frame_lo[i]);
        hi = ak_vec3_max(hi, frame_hi[i]);
        roots[i] = root_position(&p);
    }
    if (!ak_vec3_is_finite(lo) || !ak_vec3_is_finite(hi)) lo = hi = ak_vec3_zero();
    /* --follow: a box of the largest single-frame size around the root, offset by the mean
     * of (frame centre - root) so the body sits in it as it does on average */
    ak_vec3 follow_size = ak_vec3_zero(), follow_offset = ak_vec3_zero();
    size_t framed = 0;
    for (size_t i = 0; i < ft.count; ++i) {
        if (!ak_vec3_is_finite(frame_lo[i]) || !ak_vec3_is_finite(frame_hi[i])) continue;
        follow_size = ak_vec3_max(follow_size, ak_vec3_sub(frame_hi[i], frame_lo[i]));
        ak_vec3 c = ak_vec3_scale(ak_vec3_add(frame_lo[i], frame_hi[i]), 0.5f);
        if (!ak_vec3_is_finite(roots[i])) roots[i] = c;
        follow_offset = ak_vec3_add(follow_offset, ak_vec3_sub(c, roots[i]));
        ++framed;
    }
    if (framed) follow_offset = ak_vec3_scale(follow_offset, 1.0f / (float)framed);
    if (!follow && framed > 1) {
        /* a path much longer than the body: say how to keep the body large */
        float body = ak_maxf(ak_maxf(follow_size.x, follow_size.y), follow_size.z);
        float path = ak_maxf(hi.x - lo.x, hi.z - lo.z);
        if (body > 0.0f && path > 2.0f * body)
            fprintf(stderr, "note: the motion travels %.3g units, %.1f times the body's size; --follow keeps the body framed\n",
                    (double)path, (double)(path / body));
    }
    if (cli_frame_init_camera(&f, s, w, h, lo, hi, &cam)) {
        rc = cli_fail("render", "out of memory");
        goto done;
    }
    ak_view_panel panels[5];
    char strip[160];
    snprintf(strip, sizeof strip, "%s%s%s", s->name, clip >= 0 ? "  " : "", clip >= 0 ? ak_clip_name(s->clips[clip]) : "");
    pd.title = strip;
    for (size_t k = 0; k < method_count; ++k) {
        if (cli_image_alloc(&panel[k], w, h)) {
            rc = cli_fail("render", "out of memory");
            goto done;
        }
        panels[k] = (ak_view_panel){&panel[k], method_count > 1 ? labels[methods[k]] : NULL};
    }
    if (method_count > 1 && cli_image_alloc(&composed, cw, ch)) {
        rc = cli_fail("render", "out of memory");
        goto done;
    }
    const ak_image* frame_img = method_count > 1 ? &composed : &panel[0];
    /* GIF delays are whole 1/100 s: 100 fps at most */
    float rate = ft.step > 0 ? 1.0f / ft.step : 24.0f;
    if (gif && rate > 100.0f) {
        fprintf(stderr, "note: frames %.4g s apart play at 100 fps, the fastest a GIF holds\n", (double)ft.step);
        rate = 100.0f;
    }
    if (gif && ak_gif_writer_create(out, &(ak_gif_desc){.width = frame_img->width, .height = frame_img->height, .frame_rate = rate},
                                    NULL, &gw) != AK_OK) {
        rc = cli_fail("render", "%s: cannot create the file", out);
        goto done;
    }
    double t_start = cli_now();
    for (size_t i = 0; i < ft.count; ++i) {
        if (follow && ak_vec3_is_finite(roots[i])) {
            ak_vec3 c = ak_vec3_add(roots[i], follow_offset), half = ak_vec3_scale(follow_size, 0.5f);
            cli_frame_aim(&f, ak_vec3_sub(c, half), ak_vec3_add(c, half), &cam);
        }
        for (size_t k = 0; k < method_count; ++k) {
            /* soft: simulate the flesh from time 0 to the first frame (60 Hz) */
            for (int q = 0; i == 0 && methods[k] == CLI_SOFT && (float)q / 60.0f < ft.t[0]; ++q)
                if (cli_poser_pose(&p, clip, (float)q / 60.0f, false, CLI_SOFT) != AK_OK) break;
            ak_result r = cli_poser_pose(&p, clip, ft.t[i], false, methods[k]);
            char title[200];
            if (method_count > 1)
                snprintf(title, sizeof title, "t=%.2fs", (double)ft.t[i]);
            else
                snprintf(title, sizeof title, "%s  t=%.2fs  %s", strip, (double)ft.t[i], skinned ? labels[methods[0]] : "");
            cli_draw_opts o = {.skeleton = CLI_GET(&a, "--skeleton") != NULL, .colors = bone ? colors : NULL, .title = title,
                               .hidden = hidden};
            if (r == AK_OK) r = cli_frame_draw(&f, &p, &o, &panel[k]);
            if (r != AK_OK) {
                rc = cli_fail("render", "%s: %s", a.pos[0], ak_result_string(r));
                goto done;
            }
        }
        if (method_count > 1 && ak_view_panels_compose(&pd, panels, method_count, &composed) != AK_OK) {
            rc = cli_fail("render", "cannot compose panels");
            goto done;
        }
        ak_result wr;
        if (gif) {
            wr = ak_gif_writer_add_frame(gw, frame_img);
        } else if (ft.count == 1) {
            wr = ak_png_write(out, frame_img);
        } else {
            char path[1024];
            snprintf(path, sizeof path, "%.*s_%04zu.png", (int)(strlen(out) - 4), out, i);
            wr = ak_png_write(path, frame_img);
        }
        if (wr != AK_OK) {
            rc = cli_fail("render", "%s: cannot write the image: %s", out, ak_result_string(wr));
            goto done;
        }
        cli_progress("render", i + 1, ft.count);
    }
    if (gw) {
        ak_result wr = ak_gif_writer_finish(gw);
        gw = NULL;
        if (wr != AK_OK) {
            rc = cli_fail("render", "%s: cannot write the image: %s", out, ak_result_string(wr));
            goto done;
        }
    }
    double secs = cli_now() - t_start;
    if (gif)
        cli_wrote(out, "%zu frame%s %dx%d at %.4g fps in %.2f s", ft.count, cli_plural(ft.count),
                frame_img->width, frame_img->height, (double)rate, secs);
    else if (ft.count == 1)
        cli_wrote(out, "1 frame %dx%d in %.2f s", frame_img->width, frame_img->height, secs);
    else if (!cli_quiet)
        fprintf(stderr, "wrote %.*s_0000.png .. %.*s_%04zu.png: %zu frames %dx%d in %.2f s\n", (int)(strlen(out) - 4), out,
                (int)(strlen(out) - 4), out, ft.count - 1, ft.count, frame_img->width, frame_img->height, secs);
done:
    ak_gif_writer_discard(gw); /* a failed run leaves no partial GIF */
    for (size_t m = 0; colors && m < s->mesh_count; ++m) free(colors[m]);
    free(colors);
    free(hidden);
    free(frame_lo);
    free(frame_hi);
    free(roots);
    for (int k = 0; k < 5; ++k) free(panel[k].pixels);
    free(composed.pixels);
    free(ft.t);
    cli_frame_free(&f);
    cli_poser_free(&p);
    ak_scene_destroy(s);
    return rc;
}
