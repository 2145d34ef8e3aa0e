/* animkit curves: a clip's animation curves as value-versus-time charts (a read-only curve editor). */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"

static const char* const usage =
    "usage: animkit curves FILE|builtin:NAME --clip C [--joint NAME] [--size WxH] -o OUT.png\n"
    "Plot clip C's channels: one chart per channel (translation, rotation quaternion x y z w,\n"
    "scale, morph weights), time on x, value on y, one colour per component, with the keys\n"
    "marked and their in/out tangents drawn as handles. --joint keeps only that joint's\n"
    "channels. At most 24 charts; --size is the size of one chart (default 420x260).\n";

#define MAX_CHARTS 24
#define SAMPLES 240

static const char* target_name(ak_channel_target t) {
    switch (t) {
    case AK_CHANNEL_TRANSLATION: return "translation";
    case AK_CHANNEL_ROTATION: return "rotation";
    case AK_CHANNEL_SCALE: return "scale";
    case AK_CHANNEL_MORPH_WEIGHTS: return "weights";
    default: return "scalar";
    }
}

/* Draw channel c of clip into img. */
static ak_result draw_channel(const ak_scene* s, const ak_clip* clip, size_t c, const ak_image* img) {
    const ak_track* tr = ak_clip_channel_track(clip, c);
    uint32_t comps = ak_track_component_count(tr);
    if (comps > 8) comps = 8;
    size_t keys = ak_track_key_count(tr);
    float t0 = ak_track_start_time(tr), t1 = ak_track_end_time(tr);
    if (t1 <= t0) t1 = t0 + 1.0f;
    float* times = malloc(SAMPLES * sizeof(float));
    float* values = malloc(SAMPLES * ak_track_component_count(tr) * sizeof(float));
    float* comp_y = malloc((size_t)comps * SAMPLES * sizeof(float));
    float* kx = malloc(keys * sizeof(float));
    float* ky = malloc((size_t)comps * keys * sizeof(float));
    float* kin = malloc((size_t)comps * keys * sizeof(float));
    float* kout = malloc((size_t)comps * keys * sizeof(float));
    float v[16], ti[16], to[16];
    ak_result r = AK_ERR_NO_MEMORY;
    if (!times || !values || !comp_y || !kx || !ky || !kin || !kout) goto done;
    r = ak_track_sample_uniform(tr, t0, t1, (ak_f32_span){times, SAMPLES},
                                (ak_f32_span){values, SAMPLES * ak_track_component_count(tr)});
    if (r != AK_OK) goto done;
    uint32_t all = ak_track_component_count(tr);
    for (uint32_t k = 0; k < comps; ++k)
        for (size_t i = 0; i < SAMPLES; ++i) comp_y[k * SAMPLES + i] = values[i * all + k];
    ak_f32_cspan kt = ak_track_times(tr);
    for (size_t i = 0; i < keys; ++i) {
        kx[i] = kt.ptr[i];
        r = ak_track_key(tr, i, (ak_f32_span){v, 16}, (ak_f32_span){ti, 16}, (ak_f32_span){to, 16});
        if (r != AK_OK) goto done;
        for (uint32_t k = 0; k < comps; ++k) {
            ky[k * keys + i] = v[k];
            kin[k * keys + i] = ti[k];
            kout[k * keys + i] = to[k];
        }
    }
    static const char* const xyzw[4] = {"x", "y", "z", "w"};
    char labels[8][16];
    ak_view_series series[8];
    bool tangents = ak_track_interp(tr) != AK_INTERP_STEP && !ak_track_is_rotation(tr);
    for (uint32_t k = 0; k < comps; ++k) {
        if (comps <= 4) snprintf(labels[k], sizeof labels[k], "%s", xyzw[k]);
        else snprintf(labels[k], sizeof labels[k], "w%u", k);
        series[k] = (ak_view_series){
            .x = {times, SAMPLES},
            .y = {comp_y + k * SAMPLES, SAMPLES},
            .label = labels[k],
            .key_x = {kx, keys},
            .key_y = {ky + k * keys, keys},
            .key_in_slope = {tangents ? kin + k * keys : NULL, tangents ? keys : 0},
            .key_out_slope = {tangents ? kout + k * keys : NULL, tangents ? keys : 0},
        };
    }
    char title[160];
    ak_channel_target tg = ak_clip_channel_target(clip, c);
    uint32_t idx = ak_clip_channel_index(clip, c);
    const char* who = (tg <= AK_CHANNEL_SCALE && s->skeleton) ? ak_skeleton_joint_name(s->skeleton, idx) : "";
    snprintf(title, sizeof title, "%s %s (%s)", who, target_name(tg), ak_interp_name(ak_track_interp(tr)));
    ak_view_plot plot = {.series = series, .series_count = comps, .title = title, .x_label = "time (s)"};
    r = ak_view_plot_draw(&plot, img);
done:
    free(times), free(values), free(comp_y), free(kx), free(ky), free(kin), free(kout);
    return r;
}

int cmd_curves(int argc, char** argv) {
    static const cli_opt opts[] = {{"--clip", "-c", true}, {"--joint", "-j", true}, {"--size", NULL, true},
                                   {"--output", "-o", true}};
    cli_args a;
    int rc = cli_parse("curves", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 1) return cli_usage("curves", "expected one FILE or builtin:NAME");
    const char* out = CLI_GET(&a, "--output");
    if (!out) return cli_usage("curves", "missing -o OUT.png");
    if (!cli_has_ext(out, ".png")) return cli_usage("curves", "output '%s' must end in .png", out);
    if (!CLI_GET(&a, "--clip")) return cli_usage("curves", "missing --clip C");
    int w = 420, h = 260;
    if (CLI_GET(&a, "--size") && !cli_parse_size(CLI_GET(&a, "--size"), &w, &h))
        return cli_usage("curves", "--size '%s' is not WxH", CLI_GET(&a, "--size"));
    ak_scene* s = NULL;
    if ((rc = cli_load_scene("curves", a.pos[0], &s))) return rc;
    ak_image charts[MAX_CHARTS];
    ak_view_panel panels[MAX_CHARTS];
    ak_image composed = {0};
    size_t count = 0;
    memset(charts, 0, sizeof charts);
    int ci = ak_scene_find_clip(s, CLI_GET(&a, "--clip"));
    const char* joint = CLI_GET(&a, "--joint");
    int jidx = -1;
    if (ci < 0) {
        rc = cli_fail("curves", "%s: no clip '%s' (%zu clip%s)", a.pos[0], CLI_GET(&a, "--clip"), s->clip_count, cli_plural(s->clip_count));
        goto done;
    }
    if (joint && (jidx = s->skeleton ? ak_skeleton_find_joint(s->skeleton, joint) : -1) < 0) {
        rc = cli_fail("curves", "%s: no joint named '%s'", a.pos[0], joint);
        goto done;
    }
    const ak_clip* clip = s->clips[ci];
    size_t total = 0;
    for (size_t c = 0; c < ak_clip_channel_count(clip); ++c) {
        ak_channel_target tg = ak_clip_channel_target(clip, c);
        if (jidx >= 0 && (tg > AK_CHANNEL_SCALE || (int)ak_clip_channel_index(clip, c) != jidx)) continue;
        ++total;
        if (count == MAX_CHARTS) continue;
        if (cli_image_alloc(&charts[count], w, h)) {
            rc = cli_fail("curves", "out of memory");
            goto done;
        }
        ak_result r = draw_channel(s, clip, c, &charts[count]);
        if (r != AK_OK) {
            rc = cli_fail("curves", "%s: channel %zu: %s", a.pos[0], c, ak_result_string(r));
            goto done;
        }
        panels[count] = (ak_view_panel){&charts[count], NULL};
        ++count;
    }
    if (count == 0) {
        rc = cli_fail("curves", "%s: clip '%s' has no channel%s%s", a.pos[0], ak_clip_name(clip), joint ? " for joint " : "",
                      joint ? joint : "");
        goto done;
    }
    char title[200];
    snprintf(title, sizeof title, "%s (%.3f s, %zu channel%s%s)", ak_clip_name(clip), (double)ak_clip_duration(clip),
             total, total == 1 ? "" : "s", total > count ? ", first 24 shown" : "");
    ak_view_panels_desc pd = {.columns = count < 3 ? (int)count : 3, .title = title, .label_scale = 1};
    int cw, ch;
    ak_view_panels_size(&pd, count, w, h, &cw, &ch);
    if (cli_image_alloc(&composed, cw, ch) || ak_view_panels_compose(&pd, panels, count, &composed) != AK_OK ||
        ak_png_write(out, &composed) != AK_OK) {
        rc = cli_fail("curves", "%s: cannot write the image", out);
        goto done;
    }
    fprintf(stderr, "wrote %s: %zu charts\n", out, count);
done:
    for (size_t i = 0; i < MAX_CHARTS; ++i) free(charts[i].pixels);
    free(composed.pixels);
    ak_scene_destroy(s);
    return rc;
}
