/* animkit curves: a clip's animation curves as value-versus-time charts (a read-only curve editor). */
#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"

static const char* const usage =
    "usage: animkit curves FILE|builtin:NAME --clip C [--joint NAME] [--channel LIST] [--page P]\n"
    "                      [--size WxH] -o OUT.png\n"
    "Plot clip C's channels: one chart per channel (translation, rotation quaternion x y z w,\n"
    "scale, morph weights), time on x, value on y, one colour per component, with the keys\n"
    "marked and their in/out tangents drawn as handles (markers only where keys are at least\n"
    "8 pixels apart; a dense capture is drawn as its line). Charts are numbered #0, #1, ... as\n"
    "the file declares its channels. A page holds 24 charts; --size is the size of one chart\n"
    "(default 420x260, at least 120x80; the page is at most 8192x8192).\n"
    "  --joint NAME    only that joint's channels\n"
    "  --channel LIST  only these charts: numbers and ranges (3,7-9) and joint names, a name\n"
    "                  with .translation, .rotation or .scale for one channel (Hips.rotation),\n"
    "                  or a kind alone (rotation: every rotation chart)\n"
    "  --page P        page P (from 1) of the selected charts; the title says how many pages\n";

#define MAX_SIDE 8192 /* the page, like render's images */
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

/* Name of the mesh whose morph range starts at morph index idx ("" when none). */
static const char* morph_mesh_name(const ak_scene* s, uint32_t idx) {
    for (size_t m = 0, off = 0; m < s->mesh_count; ++m) {
        size_t t = s->meshes[m].mesh ? s->meshes[m].mesh->morph_target_count : 0;
        if (t && off == idx) return s->meshes[m].mesh->name;
        off += t;
    }
    return "";
}

/* Draw channel c of clip (chart number shown_index) into img. */
static ak_result draw_channel(const ak_scene* s, const ak_clip* clip, size_t c, size_t shown_index, const ak_image* img) {
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
    const char* who = (tg <= AK_CHANNEL_SCALE && s->skeleton) ? ak_skeleton_joint_name(s->skeleton, idx)
                      : tg == AK_CHANNEL_MORPH_WEIGHTS ? morph_mesh_name(s, idx)
                                                       : "";
    snprintf(title, sizeof title, "#%zu %s%s%s (%s)", shown_index, who, who[0] ? " " : "", target_name(tg),
             ak_interp_name(ak_track_interp(tr)));
    ak_view_plot plot = {.series = series, .series_count = comps, .title = title, .x_label = "time (s)"};
    r = ak_view_plot_draw(&plot, img);
done:
    free(times), free(values), free(comp_y), free(kx), free(ky), free(kin), free(kout);
    return r;
}

/* Mark the charts LIST names in sel[count] (chart k is file channel chan[k]). Returns CLI_OK,
 * or prints why not: bad usage for a malformed item, bad input for a number or joint the clip
 * does not have. */
static int select_channels(const char* file, const ak_scene* s, const ak_clip* clip, const size_t* chan, size_t count,
                           const char* list, bool* sel) {
    char buf[1024];
    if (strlen(list) >= sizeof buf) return cli_usage("curves", "--channel list is too long");
    strcpy(buf, list);
    char* save = NULL;
    for (char* tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (isdigit((unsigned char)tok[0])) {
            long lo, hi;
            char* dash = strchr(tok, '-');
            if (dash) *dash = '\0';
            if (!cli_parse_int(tok, 0, 1000000000L, &lo) || (dash && !cli_parse_int(dash + 1, 0, 1000000000L, &hi)))
                return cli_usage("curves", "--channel item '%s%s%s' is not a number or range A-B", tok, dash ? "-" : "",
                                 dash ? dash + 1 : "");
            if (!dash) hi = lo;
            if (hi < lo) return cli_usage("curves", "--channel range %ld-%ld runs backwards", lo, hi);
            if ((size_t)hi >= count)
                return cli_fail("curves", "%s: clip '%s' has %zu chart%s (#0-#%zu), no #%ld", file, ak_clip_name(clip), count,
                                cli_plural(count), count - 1, hi);
            for (long k = lo; k <= hi; ++k) sel[k] = true;
            continue;
        }
        /* JOINT or JOINT.translation|rotation|scale */
        int target = -1;
        char* dot = strrchr(tok, '.');
        if (dot) {
            if (strcmp(dot + 1, "translation") == 0) target = AK_CHANNEL_TRANSLATION;
            else if (strcmp(dot + 1, "rotation") == 0) target = AK_CHANNEL_ROTATION;
            else if (strcmp(dot + 1, "scale") == 0) target = AK_CHANNEL_SCALE;
            if (target >= 0) *dot = '\0';
        }
        int j = s->skeleton ? ak_skeleton_find_joint(s->skeleton, tok) : -1;
        if (j < 0 && !dot) { /* a bare kind: every channel of that kind (of --joint's joint, when given) */
            int kind = strcmp(tok, "translation") == 0 ? AK_CHANNEL_TRANSLATION
                       : strcmp(tok, "rotation") == 0  ? AK_CHANNEL_ROTATION
                       : strcmp(tok, "scale") == 0     ? AK_CHANNEL_SCALE
                                                       : -1;
            if (kind >= 0) {
                bool any = false;
                for (size_t k = 0; k < count; ++k)
                    if ((int)ak_clip_channel_target(clip, chan[k]) == kind) sel[k] = any = true;
                if (!any) return cli_fail("curves", "%s: clip '%s' has no %s channel", file, ak_clip_name(clip), tok);
                continue;
            }
        }
        if (j < 0)
            return cli_fail("curves", "%s: --channel: '%s' is no joint, chart number or channel kind (translation, "
                            "rotation, scale)", file, tok);
        bool any = false;
        for (size_t k = 0; k < count; ++k) {
            ak_channel_target tg = ak_clip_channel_target(clip, chan[k]);
            if (tg > AK_CHANNEL_SCALE || (int)ak_clip_channel_index(clip, chan[k]) != j || (target >= 0 && (int)tg != target))
                continue;
            sel[k] = any = true;
        }
        if (!any)
            return cli_fail("curves", "%s: clip '%s' does not animate %s%s%s", file, ak_clip_name(clip), tok,
                            target >= 0 ? "." : "", target >= 0 ? target_name((ak_channel_target)target) : "");
    }
    return CLI_OK;
}

int cli_curves_run(int argc, char** argv, bool quiet) {
    static const cli_opt opts[] = {{"--clip", "-c", true},    {"--joint", "-j", true}, {"--size", NULL, true},
                                   {"--output", "-o", true},  {"--channel", NULL, true}, {"--page", NULL, true}};
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
    /* a chart is at least 120x80 (ak_view_plot's minimum) */
    if (CLI_GET(&a, "--size") && (!cli_parse_size(CLI_GET(&a, "--size"), &w, &h) || w < 120 || h < 80))
        return cli_usage("curves", "--size '%s' is not WxH with 120..8192 x 80..8192 pixels",
                         CLI_GET(&a, "--size"));
    long page = 0;
    if (CLI_GET(&a, "--page") && !cli_parse_int(CLI_GET(&a, "--page"), 1, 1000000, &page))
        return cli_usage("curves", "--page '%s' is not a page number (from 1)", CLI_GET(&a, "--page"));
    ak_scene* s = NULL;
    if ((rc = cli_load_scene("curves", a.pos[0], &s))) return rc;
    ak_image charts[MAX_CHARTS];
    ak_view_panel panels[MAX_CHARTS];
    ak_image composed = {0};
    size_t count = 0;
    size_t* chan = NULL;
    bool* sel = NULL;
    memset(charts, 0, sizeof charts);
    int ci = ak_scene_find_clip(s, CLI_GET(&a, "--clip"));
    const char* joint = CLI_GET(&a, "--joint");
    const char* list = CLI_GET(&a, "--channel");
    int jidx = -1;
    if (ci < 0) {
        rc = cli_no_clip("curves", a.pos[0], CLI_GET(&a, "--clip"), s);
        goto done;
    }
    if (joint && (jidx = s->skeleton ? ak_skeleton_find_joint(s->skeleton, joint) : -1) < 0) {
        rc = cli_fail("curves", "%s: no joint named '%s'", a.pos[0], joint);
        goto done;
    }
    const ak_clip* clip = s->clips[ci];
    /* charts: the file's channels (a weights channel the reader split per primitive once) */
    size_t nch = ak_clip_channel_count(clip), file_count = 0;
    chan = calloc(nch + 1, sizeof(size_t));
    sel = calloc(nch + 1, sizeof(bool));
    if (!chan || !sel) {
        rc = cli_fail("curves", "out of memory");
        goto done;
    }
    for (size_t c = 0; c < nch; ++c)
        if (!cli_clip_channel_repeats(s, clip, c)) chan[file_count++] = c;
    if (list) {
        if ((rc = select_channels(a.pos[0], s, clip, chan, file_count, list, sel))) goto done;
    } else {
        for (size_t k = 0; k < file_count; ++k) sel[k] = true;
    }
    size_t selected = 0;
    for (size_t k = 0; k < file_count; ++k) {
        ak_channel_target tg = ak_clip_channel_target(clip, chan[k]);
        if (jidx >= 0 && (tg > AK_CHANNEL_SCALE || (int)ak_clip_channel_index(clip, chan[k]) != jidx)) sel[k] = false;
        selected += sel[k];
    }
    if (selected == 0) {
        rc = cli_fail("curves", "%s: clip '%s' has no channel%s%s", a.pos[0], ak_clip_name(clip), joint ? " for joint " : "",
                      joint ? joint : "");
        goto done;
    }
    size_t pages = (selected + MAX_CHARTS - 1) / MAX_CHARTS;
    if ((size_t)page > pages) {
        rc = cli_fail("curves", "%s: --page %ld, but the %zu chart%s fill %zu page%s", a.pos[0], page, selected,
                      cli_plural(selected), pages, cli_plural(pages));
        goto done;
    }
    size_t first = (page ? (size_t)page - 1 : 0) * MAX_CHARTS, rank = 0, first_shown = 0, last_shown = 0;
    {
        /* the page's size before any chart is allocated: at most MAX_SIDE on each side */
        const size_t n = selected - first < MAX_CHARTS ? selected - first : MAX_CHARTS;
        const ak_view_panels_desc probe = {.columns = n < 3 ? (int)n : 3, .title = "title", .label_scale = 1};
        int pw, ph, mw = w, mh = h;
        ak_view_panels_size(&probe, n, w, h, &pw, &ph);
        if (pw > MAX_SIDE || ph > MAX_SIDE) {
            int cw = pw, ch = ph;
            while (mw > 120 && mh > 80 && (cw > MAX_SIDE || ch > MAX_SIDE)) {
                mw = mw * 15 / 16 > 120 ? mw * 15 / 16 : 120, mh = mh * 15 / 16 > 80 ? mh * 15 / 16 : 80;
                ak_view_panels_size(&probe, n, mw, mh, &cw, &ch);
            }
            rc = cli_usage("curves", "--size %dx%d makes a %dx%d page of %zu chart%s, above the %dx%d limit (try --size %dx%d)",
                           w, h, pw, ph, n, cli_plural(n), MAX_SIDE, MAX_SIDE, mw, mh);
            goto done;
        }
    }
    for (size_t k = 0; k < file_count && count < MAX_CHARTS; ++k) {
        if (!sel[k] || rank++ < first) continue;
        if (cli_image_alloc(&charts[count], w, h)) {
            rc = cli_fail("curves", "out of memory");
            goto done;
        }
        ak_result r = draw_channel(s, clip, chan[k], k, &charts[count]);
        if (r != AK_OK) {
            rc = cli_fail("curves", "%s: channel %zu: %s", a.pos[0], k, ak_result_string(r));
            goto done;
        }
        if (count == 0) first_shown = k;
        last_shown = k;
        panels[count] = (ak_view_panel){&charts[count], NULL};
        ++count;
    }
    char title[240], pg[96] = "", part[48] = "";
    if (pages > 1) snprintf(pg, sizeof pg, "; #%zu-#%zu, page %zu of %zu", first_shown, last_shown, page ? (size_t)page : 1, pages);
    if (selected < file_count) snprintf(part, sizeof part, ", %zu selected", selected);
    snprintf(title, sizeof title, "%s (%.3f s, %zu channel%s%s%s)", ak_clip_name(clip), (double)ak_clip_duration(clip),
             file_count, cli_plural(file_count), part, pg);
    ak_view_panels_desc pd = {.columns = count < 3 ? (int)count : 3, .title = title, .label_scale = 1};
    int cw, ch;
    ak_view_panels_size(&pd, count, w, h, &cw, &ch);
    if (cli_image_alloc(&composed, cw, ch) || ak_view_panels_compose(&pd, panels, count, &composed) != AK_OK ||
        ak_png_write(out, &composed) != AK_OK) {
        rc = cli_fail("curves", "%s: cannot write the image", out);
        goto done;
    }
    if (!quiet) {
        if (pages > 1)
            cli_wrote(out, "%zu of %zu chart%s (#%zu-#%zu, page %zu of %zu; --page P for the others)", count,
                    selected, cli_plural(selected), first_shown, last_shown, page ? (size_t)page : 1, pages);
        else
            cli_wrote(out, "%zu chart%s", count, cli_plural(count));
    }
done:
    for (size_t i = 0; i < MAX_CHARTS; ++i) free(charts[i].pixels);
    free(composed.pixels);
    free(chan);
    free(sel);
    ak_scene_destroy(s);
    return rc;
}

int cmd_curves(int argc, char** argv) { return cli_curves_run(argc, argv, false); }
