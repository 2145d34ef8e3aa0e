/* animkit retarget: put a source clip (motion capture) on a target character and write the
 * target as glTF, or a GIF of source and target side by side. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render.h"

static const char* const usage =
    "usage: animkit retarget SOURCE TARGET [--map FILE] [--clip C] [--no-feet] [--unscaled]\n"
    "                        [--fps N] [--size WxH] -o OUT.glb|OUT.gltf|OUT.gif\n"
    "Put SOURCE's clip C (default the first) on TARGET (FILE or builtin:NAME) and write the\n"
    "target with that one clip as glTF 2.0, or a GIF of the source skeleton and the target side\n"
    "by side. Joints are matched by name (the same name, then humanoid bones of CMU/BVH, Mixamo,\n"
    "Unreal, VRM and builtin rigs) unless --map gives the map. docs/retarget.md has the method.\n"
    "  --map FILE   lines 'TARGET_JOINT = SOURCE_JOINT' ('#' starts a comment); only the joints\n"
    "               listed are driven, the others keep their rest pose\n"
    "  --no-feet    no foot-contact clean-up (by default feet in contact are pinned with IK)\n"
    "  --unscaled   root motion as in the source (default: scaled by the leg-length ratio)\n"
    "  --fps N      frames per second of the baked clip (default 30)\n"
    "  --size WxH   GIF panel size (default 400x400)\n";

/* ---- map files ---------------------------------------------------------------------------- */

static char* trim(char* s) {
    while (*s == ' ' || *s == '\t') ++s;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n')) s[--n] = '\0';
    return s;
}

/* Parse a map file into map[target joint] = source joint (-1 elsewhere). One line on error. */
static int read_map(const char* path, const ak_scene* src, const char* src_name, const ak_scene* dst,
                    const char* dst_name, int32_t* map) {
    size_t nt = ak_scene_joint_count(dst);
    for (size_t k = 0; k < nt; ++k) map[k] = -1;
    FILE* f = fopen(path, "r");
    if (!f) return cli_fail("retarget", "%s: cannot read the map file (%s)", path, strerror(errno));
    char line[1024];
    int rc = CLI_OK;
    size_t entries = 0;
    for (long ln = 1; rc == CLI_OK && fgets(line, sizeof line, f); ++ln) {
        if (!strchr(line, '\n') && !feof(f)) {
            rc = cli_fail("retarget", "%s:%ld: line longer than %zu bytes", path, ln, sizeof line - 2);
            break;
        }
        char* hash = strchr(line, '#');
        if (hash) *hash = '\0';
        char* s = trim(line);
        if (!*s) continue;
        char* eq = strchr(s, '=');
        if (!eq) {
            rc = cli_fail("retarget", "%s:%ld: expected 'TARGET_JOINT = SOURCE_JOINT'", path, ln);
            break;
        }
        *eq = '\0';
        char* t = trim(s);
        char* so = trim(eq + 1);
        if (!*t || !*so) {
            rc = cli_fail("retarget", "%s:%ld: expected 'TARGET_JOINT = SOURCE_JOINT'", path, ln);
            break;
        }
        int tj = dst->skeleton ? ak_skeleton_find_joint(dst->skeleton, t) : -1;
        int sj = src->skeleton ? ak_skeleton_find_joint(src->skeleton, so) : -1;
        if (tj < 0) rc = cli_fail("retarget", "%s:%ld: target %s has no joint '%s'", path, ln, dst_name, t);
        else if (sj < 0) rc = cli_fail("retarget", "%s:%ld: source %s has no joint '%s'", path, ln, src_name, so);
        else if (map[tj] >= 0) rc = cli_fail("retarget", "%s:%ld: target joint '%s' is mapped twice", path, ln, t);
        else map[tj] = sj, ++entries;
    }
    if (rc == CLI_OK && ferror(f)) rc = cli_fail("retarget", "%s: read error", path);
    fclose(f);
    if (rc == CLI_OK && entries == 0) rc = cli_fail("retarget", "%s: the map file maps no joint", path);
    return rc;
}

/* ---- GIF ------------------------------------------------------------------------------------ */

static int write_gif(const char* out, const ak_scene* src, int clip, const ak_scene* dst, int w, int h) {
    const ak_scene* scenes[2] = {src, dst};
    cli_poser p[2];
    cli_frame fr[2];
    ak_image panel[2] = {{0}}, composed = {0};
    ak_gif_writer* gw = NULL;
    memset(p, 0, sizeof p);
    memset(fr, 0, sizeof fr);
    int rc = CLI_OK;
    int clips[2] = {clip, 0};
    float duration = ak_clip_duration(dst->clips[0]);
    size_t frames = (size_t)floor((double)duration * 24.0 + 1e-6) + 1;
    if (frames > 10000) frames = 10000;
    for (int k = 0; k < 2 && rc == CLI_OK; ++k) {
        if (cli_poser_init(&p[k], scenes[k])) {
            rc = cli_fail("retarget", "out of memory");
            break;
        }
        ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
        for (size_t i = 0; i < frames && rc == CLI_OK; ++i) {
            ak_result r = cli_poser_pose(&p[k], clips[k], (float)i / 24.0f, false, CLI_LBS);
            if (r != AK_OK) rc = cli_fail("retarget", "%s: cannot pose: %s", scenes[k]->name, ak_result_string(r));
            cli_bounds_add_pose(&p[k], &lo, &hi);
        }
        if (!ak_vec3_is_finite(lo) || !ak_vec3_is_finite(hi)) lo = hi = ak_vec3_zero();
        if (rc == CLI_OK && (cli_frame_init(&fr[k], scenes[k], w, h, lo, hi, 0.55f) || cli_image_alloc(&panel[k], w, h)))
            rc = cli_fail("retarget", "out of memory");
    }
    ak_view_panels_desc pd = {.title = "animkit retarget"};
    int cw = 0, ch = 0;
    ak_view_panels_size(&pd, 2, w, h, &cw, &ch);
    if (rc == CLI_OK && cli_image_alloc(&composed, cw, ch)) rc = cli_fail("retarget", "out of memory");
    if (rc == CLI_OK &&
        ak_gif_writer_create(out, &(ak_gif_desc){.width = cw, .height = ch, .delay_cs = 4}, NULL, &gw) != AK_OK)
        rc = cli_fail("retarget", "%s: cannot create the file", out);
    ak_view_panel panels[2] = {{&panel[0], "source"}, {&panel[1], "target"}};
    for (size_t i = 0; i < frames && rc == CLI_OK; ++i) {
        for (int k = 0; k < 2 && rc == CLI_OK; ++k) {
            char title[160];
            snprintf(title, sizeof title, "%s  t=%.2fs", scenes[k]->name, (double)i / 24.0);
            cli_draw_opts o = {.skeleton = true, .title = title};
            ak_result r = cli_poser_pose(&p[k], clips[k], (float)i / 24.0f, false, CLI_LBS);
            if (r == AK_OK) r = cli_frame_draw(&fr[k], &p[k], &o, &panel[k]);
            if (r != AK_OK) rc = cli_fail("retarget", "%s: %s", scenes[k]->name, ak_result_string(r));
        }
        if (rc == CLI_OK && ak_view_panels_compose(&pd, panels, 2, &composed) != AK_OK) rc = cli_fail("retarget", "cannot compose panels");
        if (rc == CLI_OK && ak_gif_writer_add_frame(gw, &composed) != AK_OK) rc = cli_fail("retarget", "%s: cannot write", out);
    }
    if (gw) {
        ak_result wr = ak_gif_writer_finish(gw);
        if (rc == CLI_OK && wr != AK_OK) rc = cli_fail("retarget", "%s: cannot write: %s", out, ak_result_string(wr));
    }
    for (int k = 0; k < 2; ++k) {
        cli_frame_free(&fr[k]);
        cli_poser_free(&p[k]);
        free(panel[k].pixels);
    }
    free(composed.pixels);
    if (rc == CLI_OK) fprintf(stderr, "wrote %s: %zu frames %dx%d\n", out, frames, cw, ch);
    return rc;
}

/* ---- command -------------------------------------------------------------------------------- */

int cmd_retarget(int argc, char** argv) {
    static const cli_opt opts[] = {{"--map", NULL, true},      {"--clip", "-c", true}, {"--no-feet", NULL, false},
                                   {"--unscaled", NULL, false}, {"--fps", NULL, true},  {"--size", NULL, true},
                                   {"--output", "-o", true}};
    cli_args a;
    int rc = cli_parse("retarget", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 2) return cli_usage("retarget", "expected SOURCE and TARGET");
    const char* out = CLI_GET(&a, "--output");
    if (!out) return cli_usage("retarget", "missing -o OUT.glb|OUT.gltf|OUT.gif");
    bool gif = cli_has_ext(out, ".gif");
    if (!gif && !cli_has_ext(out, ".glb") && !cli_has_ext(out, ".gltf"))
        return cli_usage("retarget", "output '%s' must end in .glb, .gltf or .gif", out);
    float fps = 30.0f;
    if (CLI_GET(&a, "--fps") && (!cli_parse_float(CLI_GET(&a, "--fps"), &fps) || !(fps >= 1.0f) || fps > 1000.0f))
        return cli_usage("retarget", "--fps '%s' is not a number in [1, 1000]", CLI_GET(&a, "--fps"));
    int w = 400, h = 400;
    if (CLI_GET(&a, "--size") && !cli_parse_size(CLI_GET(&a, "--size"), &w, &h))
        return cli_usage("retarget", "--size '%s' is not WxH with 8..8192 pixels each", CLI_GET(&a, "--size"));

    ak_scene *src = NULL, *dst = NULL;
    int32_t* map = NULL;
    ak_clip* clip = NULL;
    if ((rc = cli_load_scene("retarget", a.pos[0], &src))) return rc;
    if ((rc = cli_load_scene("retarget", a.pos[1], &dst))) goto done;
    if (!src->skeleton || !dst->skeleton) {
        rc = cli_fail("retarget", "%s: has no skeleton", !src->skeleton ? a.pos[0] : a.pos[1]);
        goto done;
    }
    int ci = src->clip_count ? 0 : -1;
    if (CLI_GET(&a, "--clip")) ci = ak_scene_find_clip(src, CLI_GET(&a, "--clip"));
    if (ci < 0) {
        if (CLI_GET(&a, "--clip"))
            rc = cli_fail("retarget", "%s: no clip '%s' (%zu clip%s)", a.pos[0], CLI_GET(&a, "--clip"), src->clip_count,
                          cli_plural(src->clip_count));
        else
            rc = cli_fail("retarget", "%s: the source has no clip", a.pos[0]);
        goto done;
    }
    size_t nt = ak_scene_joint_count(dst);
    if (!(map = malloc(nt * sizeof *map))) {
        rc = cli_fail("retarget", "out of memory");
        goto done;
    }
    size_t mapped = 0;
    if (CLI_GET(&a, "--map")) {
        if ((rc = read_map(CLI_GET(&a, "--map"), src, a.pos[0], dst, a.pos[1], map))) goto done;
    } else {
        ak_retarget_map_by_name(src->skeleton, dst->skeleton, (ak_i32_span){map, nt}, &mapped);
        if (!mapped) {
            rc = cli_fail("retarget", "%s: no joint matches a joint of %s by name; give --map FILE", a.pos[1], a.pos[0]);
            goto done;
        }
    }
    ak_retarget_desc d = {.source = src->skeleton, .clip = src->clips[ci], .target = dst->skeleton,
                          .source_of_target = {map, nt}, .frame_rate = fps,
                          .unscaled_root_motion = CLI_GET(&a, "--unscaled") != NULL,
                          .skip_foot_contacts = CLI_GET(&a, "--no-feet") != NULL};
    ak_retarget_stats st;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_result r = ak_retarget_clip(&d, NULL, &clip, &st, &diag);
    if (r != AK_OK) {
        rc = cli_fail("retarget", "%s -> %s: %s", a.pos[0], a.pos[1], diag.message[0] ? diag.message : ak_result_string(r));
        goto done;
    }
    fprintf(stderr, "retargeted '%s': %zu frame%s, %zu of %zu target joint%s driven, root motion x%.4g, %zu foot frame%s "
                    "in contact, %zu pinned (%zu out of reach)\n",
            ak_clip_name(clip), st.frame_count, cli_plural(st.frame_count), st.mapped_count, nt, cli_plural(nt),
            (double)st.root_scale, st.contact_frames, cli_plural(st.contact_frames), st.pinned_frames, st.unreached_frames);
    /* the target with this one clip (a shallow copy: the scene keeps its own clips) */
    ak_scene view = *dst;
    view.clips = &clip;
    view.clip_count = 1;
    if (gif) {
        rc = write_gif(out, src, ci, &view, w, h);
    } else {
        ak_io_save_desc sd = {0};
        r = ak_io_save(out, &view, &sd, &diag);
        if (r != AK_OK) rc = cli_fail("retarget", "%s: %s", out, diag.message[0] ? diag.message : ak_result_string(r));
        else fprintf(stderr, "wrote %s\n", out);
    }
done:
    ak_clip_destroy(clip);
    free(map);
    ak_scene_destroy(src);
    ak_scene_destroy(dst);
    return rc;
}
