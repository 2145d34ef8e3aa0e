/* animkit render: a posed or animated model to PNG or GIF, optionally LBS | DQS | CoR side by side. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"

static const char* const usage =
    "usage: animkit render FILE|builtin:NAME [--clip C] [--time T | --frames A:B:STEP |\n"
    "                      --fps F --duration D] [--method lbs|dqs|cor|all] [--size WxH]\n"
    "                      [--skeleton] [--weights BONE] -o OUT.png|OUT.gif\n"
    "Render the model posed by clip C (default the first) with an orbit camera framing the\n"
    "whole motion. Times: --time T (one frame), --frames A:B:STEP (A to B inclusive, in\n"
    "seconds), or --fps F --duration D (frames at 0, 1/F, ... before D). A GIF without times\n"
    "plays the whole clip at 24 fps; a PNG without times shows t = 0. Several frames into a\n"
    "PNG write OUT_0000.png, OUT_0001.png, ...\n"
    "  --method all   LBS | DQS | CoR in labelled panels side by side\n"
    "  --size WxH     output size of one panel (default 640x480)\n"
    "  --skeleton     overlay the skeleton\n"
    "  --weights BONE colour the meshes by BONE's skin weights (blue 0 -> red 1)\n"
    "Formats this build writes: png gif.\n";

typedef struct frame_times {
    float* t;
    size_t count;
} frame_times;

static int parse_times(cli_args* a, const cli_opt* opts, size_t nopts, bool gif, float clip_duration, frame_times* out) {
    const char* time = cli_get(a, opts, nopts, "--time");
    const char* frames = cli_get(a, opts, nopts, "--frames");
    const char* fps = cli_get(a, opts, nopts, "--fps");
    const char* dur = cli_get(a, opts, nopts, "--duration");
    int given = (time != NULL) + (frames != NULL) + (fps != NULL || dur != NULL);
    if (given > 1) return cli_usage("render", "use one of --time, --frames, or --fps with --duration");
    float t0 = 0, t1 = 0, step = 0;
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
        if (!fps || !dur) return cli_usage("render", "--fps and --duration go together");
        if (!cli_parse_float(fps, &f) || !(f > 0) || f > 1000) return cli_usage("render", "--fps '%s' is not a rate in (0, 1000]", fps);
        if (!cli_parse_float(dur, &d) || !(d > 0)) return cli_usage("render", "--duration '%s' is not a number > 0", dur);
        t0 = 0;
        step = 1.0f / f;
        t1 = d - 0.5f * step;
    } else if (gif && clip_duration > 0) {
        step = 1.0f / 24.0f;
        t1 = clip_duration;
    } else {
        step = 1;
    }
    double count = floor((double)(t1 - t0) / (double)step + 1e-6) + 1.0;
    if (count > 10000) return cli_usage("render", "%.0f frames is too many (at most 10000)", count);
    out->count = (size_t)count;
    out->t = calloc(out->count, sizeof(float));
    if (!out->t) return cli_fail("render", "out of memory");
    for (size_t i = 0; i < out->count; ++i) out->t[i] = t0 + (float)((double)i * (double)step);
    return CLI_OK;
}

/* Render frame times into images (one panel per method) and hand each composed frame to sink. */
int cmd_render(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--clip", "-c", true}, {"--time", "-t", true},   {"--frames", NULL, true},  {"--fps", NULL, true},
        {"--duration", NULL, true}, {"--method", "-m", true}, {"--size", NULL, true}, {"--skeleton", NULL, false},
        {"--weights", NULL, true}, {"--output", "-o", true},
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
    cli_method methods[3] = {CLI_LBS, CLI_DQS, CLI_COR};
    size_t method_count = 1;
    const char* ms = CLI_GET(&a, "--method");
    if (ms && strcmp(ms, "all") == 0) method_count = 3;
    else if (ms && !cli_method_parse(ms, &methods[0])) return cli_usage("render", "--method must be lbs, dqs, cor or all, not '%s'", ms);
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
    ak_image panel[3] = {{0}}, composed = {0};
    ak_vec4** colors = NULL;
    ak_gif_writer* gw = NULL;
    memset(&p, 0, sizeof p);
    memset(&f, 0, sizeof f);
    int clip = -1;
    if (CLI_GET(&a, "--clip")) {
        clip = ak_scene_find_clip(s, CLI_GET(&a, "--clip"));
        if (clip < 0) {
            rc = cli_fail("render", "%s: no clip '%s' (%zu clips)", a.pos[0], CLI_GET(&a, "--clip"), s->clip_count);
            goto done;
        }
    } else if (s->clip_count) {
        clip = 0;
    }
    if (!(colors = calloc(s->mesh_count + 1, sizeof(ak_vec4*)))) {
        rc = cli_fail("render", "out of memory");
        goto done;
    }
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
    if ((rc = parse_times(&a, opts, nopts, gif, clip >= 0 ? ak_clip_duration(s->clips[clip]) : 0.0f, &ft))) goto done;
    if (cli_poser_init(&p, s)) {
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
        cli_bounds_add_pose(&p, &lo, &hi);
    }
    if (!ak_vec3_is_finite(lo) || !ak_vec3_is_finite(hi)) lo = hi = ak_vec3_zero();
    if (cli_frame_init(&f, s, w, h, lo, hi, 0.55f)) {
        rc = cli_fail("render", "out of memory");
        goto done;
    }
    static const char* const labels[3] = {"LBS", "DQS", "CoR"};
    ak_view_panel panels[3];
    char strip[160];
    snprintf(strip, sizeof strip, "%s%s%s", s->name, clip >= 0 ? "  " : "", clip >= 0 ? ak_clip_name(s->clips[clip]) : "");
    ak_view_panels_desc pd = {.title = strip};
    int cw = w, ch = h;
    if (method_count > 1) ak_view_panels_size(&pd, method_count, w, h, &cw, &ch);
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
    if (gif && ak_gif_writer_create(out, &(ak_gif_desc){.width = frame_img->width, .height = frame_img->height, .delay_cs = 4}, NULL, &gw) != AK_OK) {
        rc = cli_fail("render", "%s: cannot create the file", out);
        goto done;
    }
    double t_start = cli_now();
    for (size_t i = 0; i < ft.count; ++i) {
        for (size_t k = 0; k < method_count; ++k) {
            ak_result r = cli_poser_pose(&p, clip, ft.t[i], false, methods[k]);
            char title[200];
            if (method_count > 1)
                snprintf(title, sizeof title, "t=%.2fs", (double)ft.t[i]);
            else
                snprintf(title, sizeof title, "%s  t=%.2fs  %s", strip, (double)ft.t[i], skinned ? labels[methods[0]] : "");
            cli_draw_opts o = {.skeleton = CLI_GET(&a, "--skeleton") != NULL, .colors = bone ? colors : NULL, .title = title};
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
    fprintf(stderr, "wrote %s: %zu frame%s %dx%d in %.2f s\n", out, ft.count, ft.count == 1 ? "" : "s", frame_img->width,
            frame_img->height, cli_now() - t_start);
done:
    if (gw) ak_gif_writer_finish(gw);
    for (size_t m = 0; colors && m < s->mesh_count; ++m) free(colors[m]);
    free(colors);
    for (int k = 0; k < 3; ++k) free(panel[k].pixels);
    free(composed.pixels);
    free(ft.t);
    cli_frame_free(&f);
    cli_poser_free(&p);
    ak_scene_destroy(s);
    return rc;
}
