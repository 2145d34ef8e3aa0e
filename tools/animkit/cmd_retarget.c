/* animkit retarget: put a source clip (motion capture) on a target character and write the
 * target as glTF, or a GIF of source and target side by side. */
#include <errno.h>
#include <fcntl.h> /* open: O_NONBLOCK for the map file */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h> /* read, close */

#include "outfile.h"
#include "render.h"

static const char* const usage =
    "usage: animkit retarget SOURCE TARGET [--map FILE] [--map-out FILE] [--report FILE]\n"
    "                        [--clip C] [--no-feet] [--unscaled] [--fps N] [--size WxH]\n"
    "                        -o OUT.glb|OUT.gltf|OUT.gif\n"
    "Put SOURCE's clip C (default the first) on TARGET (FILE or builtin:NAME) and write the\n"
    "target with that one clip as glTF 2.0, or a GIF of the source skeleton and the target side\n"
    "by side. Without --map, joints are mapped automatically: both skeletons are fitted to a\n"
    "humanoid template (hips, spine, chest, neck, head, clavicles, arms, hands, legs, feet, toes)\n"
    "by topology, rest-pose geometry and name hints, and the map is printed as a table on stderr\n"
    "(a map file). A skeleton that is not a humanoid (a quadruped) is refused (exit 1) unless\n"
    "neither is and joint names match. docs/retarget.md has the method.\n"
    "  --map FILE      lines 'TARGET_JOINT = SOURCE_JOINT' ('#' starts a comment); only the\n"
    "                  joints listed are driven, the others keep their rest pose\n"
    "  --map-out FILE  write the map used (the automatic one: the table) as a map file to edit\n"
    "                  and pass back with --map\n"
    "  --report FILE   write the table to FILE instead of stderr\n"
    "  --no-feet       no foot-contact clean-up (by default feet in contact are pinned with IK)\n"
    "  --unscaled      root motion as in the source (default: scaled by the leg-length ratio)\n"
    "  --fps N         frames per second of the baked clip (default 30)\n"
    "  --size WxH      GIF panel size (default 400x400)\n";

/* ---- map files ---------------------------------------------------------------------------- */

#define MAX_MAP_SIZE (1u << 20)

/* Read a map file and parse it (ak_retarget_map_parse) into map[target joint] = source joint.
 * Only a regular file is read: a FIFO would block the open (and a read) forever, a directory
 * or a device is no map. One line on error. */
static int read_map(const char* path, const ak_scene* src, const char* src_name, const ak_scene* dst,
                    const char* dst_name, int32_t* map) {
    struct stat st;
    if (stat(path, &st) != 0) return cli_fail("retarget", "%s: cannot read the map file (%s)", path, strerror(errno));
    if (!S_ISREG(st.st_mode)) return cli_fail("retarget", "%s: the map file is not a regular file", path);
    /* O_NONBLOCK: the path may have become a FIFO since the stat; fstat decides */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return cli_fail("retarget", "%s: cannot read the map file (%s)", path, strerror(errno));
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return cli_fail("retarget", "%s: the map file is not a regular file", path);
    }
    if ((unsigned long long)st.st_size > MAX_MAP_SIZE) {
        close(fd);
        return cli_fail("retarget", "%s: the map file is larger than %u bytes", path, MAX_MAP_SIZE);
    }
    char* text = malloc((size_t)st.st_size + 1);
    size_t n = 0;
    bool err = !text;
    while (!err && n <= (size_t)st.st_size) { /* one byte past the size: the file may have grown */
        ssize_t got = read(fd, text + n, (size_t)st.st_size + 1 - n);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) err = true;
        if (got <= 0) break;
        n += (size_t)got;
    }
    close(fd);
    if (err || n > (size_t)st.st_size) {
        free(text);
        return cli_fail("retarget", "%s: cannot read the map file%s", path, err ? "" : " (it changed while read)");
    }
    size_t nt = ak_scene_joint_count(dst), mapped = 0;
    ak_diag diag;
    ak_result r = ak_retarget_map_parse(text, n, src->skeleton, dst->skeleton, (ak_i32_span){map, nt}, &mapped, &diag);
    free(text);
    if (r == AK_ERR_NOT_FOUND)
        return cli_fail("retarget", "%s: %s (target %s, source %s)", path, diag.message, dst_name, src_name);
    if (r != AK_OK) return cli_fail("retarget", "%s: %s", path, diag.message);
    return CLI_OK;
}

/* ---- automatic map ------------------------------------------------------------------------ */

/* The map as text (ak_retarget_map_write); NULL when out of memory. */
static char* map_text(const ak_scene* src, const ak_humanoid_roles* sr, const ak_scene* dst,
                      const ak_humanoid_roles* tr, const int32_t* map) {
    size_t nt = ak_scene_joint_count(dst), need = 0;
    ak_i32_cspan m = {map, nt};
    if (ak_retarget_map_write(src->skeleton, sr, dst->skeleton, tr, m, NULL, 0, &need) != AK_OK) return NULL;
    char* text = malloc(need + 1);
    if (text && ak_retarget_map_write(src->skeleton, sr, dst->skeleton, tr, m, text, need + 1, NULL) != AK_OK) {
        free(text);
        text = NULL;
    }
    return text;
}

static int write_text(const char* path, const char* text) {
    cli_outfile o;
    if (cli_outfile_open(&o, "retarget", path)) return CLI_BAD_INPUT;
    fputs(text, o.f);
    if (cli_outfile_commit(&o, "retarget")) return CLI_BAD_INPUT;
    cli_wrote(path, NULL);
    return CLI_OK;
}

/* Map automatically: both skeletons fitted to the humanoid template and mapped by roles; the
 * table goes to stderr or --report FILE. Neither a humanoid: joint names. */
static int auto_map(const ak_scene* src, const char* src_name, const ak_scene* dst, const char* dst_name,
                    const char* report, int32_t* map, char** out_text) {
    ak_humanoid_roles sr, tr;
    ak_diag sd, td;
    memset(&sd, 0, sizeof sd), memset(&td, 0, sizeof td);
    ak_result a = ak_humanoid_roles_find(src->skeleton, NULL, &sr, &sd);
    ak_result b = ak_humanoid_roles_find(dst->skeleton, NULL, &tr, &td);
    size_t nt = ak_scene_joint_count(dst), mapped = 0;
    if ((a != AK_OK && a != AK_ERR_NOT_FOUND) || (b != AK_OK && b != AK_ERR_NOT_FOUND))
        return cli_fail("retarget", "%s: %s", a != AK_OK && a != AK_ERR_NOT_FOUND ? src_name : dst_name,
                        a != AK_OK && a != AK_ERR_NOT_FOUND ? sd.message : td.message);
    if (a == AK_ERR_NOT_FOUND && b == AK_ERR_NOT_FOUND) {
        ak_retarget_map_by_name(src->skeleton, dst->skeleton, (ak_i32_span){map, nt}, &mapped);
        if (!mapped)
            return cli_fail("retarget", "neither %s nor %s is a humanoid (%s; %s) and no joint name matches; give --map FILE",
                            src_name, dst_name, sd.message, td.message);
        if (!(*out_text = map_text(src, NULL, dst, NULL, map))) return cli_fail("retarget", "out of memory");
        if (!cli_quiet)
            fprintf(stderr, "animkit retarget: note: neither skeleton is a humanoid: %zu joint%s matched by name\n",
                    mapped, cli_plural(mapped));
        return report ? write_text(report, *out_text) : CLI_OK;
    }
    ak_retarget_map_by_roles(src->skeleton, &sr, dst->skeleton, &tr, (ak_i32_span){map, nt}, &mapped);
    char* text = map_text(src, &sr, dst, &tr, map);
    if (!text) return cli_fail("retarget", "out of memory");
    int rc = CLI_OK;
    if (report) rc = write_text(report, text);
    else if (!cli_quiet || a != AK_OK || b != AK_OK) fputs(text, stderr);
    if (rc == CLI_OK && (a != AK_OK || b != AK_OK))
        rc = cli_fail("retarget", "%s: %s; the table above shows what matched; give --map FILE", a != AK_OK ? src_name : dst_name,
                      a != AK_OK ? sd.message : td.message);
    if (rc == CLI_OK) *out_text = text;
    else free(text);
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
    /* Each panel follows its figure (a walk travels several body lengths: framing the whole path
     * left the figures a quarter of the panel high): a box of the largest single-frame size of
     * the pose, around the root plus the mean offset of the pose's centre from it; both panels
     * look from the same angles, so both figures face the same way on screen. */
    ak_vec3 size[2], offset[2];
    ak_vec3* roots[2] = {calloc(frames, sizeof(ak_vec3)), calloc(frames, sizeof(ak_vec3))};
    if (!roots[0] || !roots[1]) rc = cli_fail("retarget", "out of memory");
    const cli_camera cam = {.has_angles = true, .yaw = ak_degrees(0.55f), .pitch = ak_degrees(0.22f)};
    for (int k = 0; k < 2 && rc == CLI_OK; ++k) {
        if (cli_poser_init(&p[k], scenes[k])) {
            rc = cli_fail("retarget", "out of memory");
            break;
        }
        ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
        size[k] = offset[k] = ak_vec3_zero();
        size_t framed = 0;
        for (size_t i = 0; i < frames && rc == CLI_OK; ++i) {
            ak_result r = cli_poser_pose(&p[k], clips[k], (float)i / 24.0f, false, CLI_LBS);
            if (r != AK_OK) rc = cli_fail("retarget", "%s: cannot pose: %s", scenes[k]->name, ak_result_string(r));
            ak_vec3 flo = ak_vec3_splat(INFINITY), fhi = ak_vec3_splat(-INFINITY);
            cli_bounds_add_pose(&p[k], &flo, &fhi);
            roots[k][i] = ak_vec3_splat(NAN);
            for (size_t j = 0; j < p[k].joint_count; ++j)
                if (!scenes[k]->is_joint || scenes[k]->is_joint[j]) {
                    roots[k][i] = ak_mat4_get_translation(p[k].world[j]);
                    break;
                }
            if (!ak_vec3_is_finite(flo) || !ak_vec3_is_finite(fhi)) continue;
            lo = ak_vec3_min(lo, flo), hi = ak_vec3_max(hi, fhi);
            ak_vec3 c = ak_vec3_scale(ak_vec3_add(flo, fhi), 0.5f);
            if (!ak_vec3_is_finite(roots[k][i])) roots[k][i] = c;
            size[k] = ak_vec3_max(size[k], ak_vec3_sub(fhi, flo));
            offset[k] = ak_vec3_add(offset[k], ak_vec3_sub(c, roots[k][i]));
            ++framed;
        }
        if (framed) offset[k] = ak_vec3_scale(offset[k], 1.0f / (float)framed);
        if (!ak_vec3_is_finite(lo) || !ak_vec3_is_finite(hi)) lo = hi = ak_vec3_zero();
        if (rc == CLI_OK && (cli_frame_init_camera(&fr[k], scenes[k], w, h, lo, hi, &cam) || cli_image_alloc(&panel[k], w, h)))
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
            /* the mesh first: the skeleton is drawn only for a figure without one (a BVH) */
            cli_draw_opts o = {.skeleton = scenes[k]->mesh_count == 0, .title = title};
            if (ak_vec3_is_finite(roots[k][i])) {
                ak_vec3 c = ak_vec3_add(roots[k][i], offset[k]), half = ak_vec3_scale(size[k], 0.5f);
                cli_frame_aim(&fr[k], ak_vec3_sub(c, half), ak_vec3_add(c, half), &cam);
            }
            ak_result r = cli_poser_pose(&p[k], clips[k], (float)i / 24.0f, false, CLI_LBS);
            if (r == AK_OK) r = cli_frame_draw(&fr[k], &p[k], &o, &panel[k]);
            if (r != AK_OK) rc = cli_fail("retarget", "%s: %s", scenes[k]->name, ak_result_string(r));
        }
        if (rc == CLI_OK && ak_view_panels_compose(&pd, panels, 2, &composed) != AK_OK) rc = cli_fail("retarget", "cannot compose panels");
        if (rc == CLI_OK && ak_gif_writer_add_frame(gw, &composed) != AK_OK) rc = cli_fail("retarget", "%s: cannot write", out);
    }
    if (gw && rc != CLI_OK) ak_gif_writer_discard(gw); /* a failed run leaves no partial GIF */
    else if (gw) {
        ak_result wr = ak_gif_writer_finish(gw);
        if (wr != AK_OK) rc = cli_fail("retarget", "%s: cannot write: %s", out, ak_result_string(wr));
    }
    for (int k = 0; k < 2; ++k) {
        cli_frame_free(&fr[k]);
        cli_poser_free(&p[k]);
        free(panel[k].pixels);
        free(roots[k]);
    }
    free(composed.pixels);
    if (rc == CLI_OK) cli_wrote(out, "%zu frames %dx%d", frames, cw, ch);
    return rc;
}

/* ---- command -------------------------------------------------------------------------------- */

int cmd_retarget(int argc, char** argv) {
    static const cli_opt opts[] = {{"--map", NULL, true},      {"--clip", "-c", true}, {"--no-feet", NULL, false},
                                   {"--unscaled", NULL, false}, {"--fps", NULL, true},  {"--size", NULL, true},
                                   {"--output", "-o", true}, {"--map-out", NULL, true},
                                   {"--report", NULL, true}};
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
    char* text = NULL;
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
            rc = cli_no_clip("retarget", a.pos[0], CLI_GET(&a, "--clip"), src);
        else
            rc = cli_fail("retarget", "%s: the source has no clip", a.pos[0]);
        goto done;
    }
    size_t nt = ak_scene_joint_count(dst);
    if (!(map = malloc(nt * sizeof *map))) {
        rc = cli_fail("retarget", "out of memory");
        goto done;
    }
    if (CLI_GET(&a, "--map")) {
        if ((rc = read_map(CLI_GET(&a, "--map"), src, a.pos[0], dst, a.pos[1], map))) goto done;
        if (CLI_GET(&a, "--map-out") && !(text = map_text(src, NULL, dst, NULL, map))) {
            rc = cli_fail("retarget", "out of memory");
            goto done;
        }
    } else if ((rc = auto_map(src, a.pos[0], dst, a.pos[1], CLI_GET(&a, "--report"), map, &text))) {
        goto done;
    }
    if (CLI_GET(&a, "--map-out") && text && (rc = write_text(CLI_GET(&a, "--map-out"), text))) goto done;
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
        else cli_wrote(out, NULL);
    }
done:
    free(text);
    ak_clip_destroy(clip);
    free(map);
    ak_scene_destroy(src);
    ak_scene_destroy(dst);
    return rc;
}
