/* animkit export: the scene's meshes posed at a time, as Wavefront OBJ; or the whole scene
 * (skeleton, skins, meshes, morph targets, clips) as glTF 2.0 when OUT ends in .glb/.gltf. */
#include <string.h>

#include "cli.h"

static const char* const usage =
    "usage: animkit export FILE|builtin:NAME [--clip N|NAME] [--time T] [--bind]\n"
    "                      [--method lbs|dqs|cor|implicit|soft] -o OUT.obj|OUT.glb|OUT.gltf\n"
    "OUT.glb / OUT.gltf (+ OUT.bin): the whole scene as glTF 2.0 (every node, skin, mesh, morph\n"
    "target and clip; keys kept as they are); --clip, --time, --bind and --method apply to OBJ.\n"
    "Write the meshes posed at time T (default 0) of a clip (default the first) as OBJ with\n"
    "normals: morphed, then skinned, in world space as glTF 2.0 defines it (a skinned vertex is\n"
    "sum_j w_j world(joint_j) inverseBind_j p, the mesh node's own transform ignored; an\n"
    "unskinned mesh is moved by its node's world matrix). One 'o' group per mesh primitive in\n"
    "file order, vertices in file order. Times outside the clip clamp to its ends. A file with\n"
    "no mesh (a BVH: skeleton and motion only) is an error: exit 1, \"no mesh to export\".\n"
    "  --bind     write every mesh's vertices as stored (bind space: no clip, no skinning,\n"
    "             no morphing, no node transform)\n"
    "  --method   skinning method (default lbs); soft simulates the flesh from time 0 to --time\n";

static void export_warn(ak_log_level level, const char* message, void* user) {
    (void)level;
    (void)user;
    fprintf(stderr, "animkit export: warning: %s\n", message);
}

/* The whole scene as glTF 2.0 (ak_io_save picks .glb or .gltf + .bin by the extension). */
static int export_gltf(const char* in, const char* out) {
    ak_scene* s = NULL;
    int rc = cli_load_scene("export", in, &s);
    if (rc) return rc;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_io_save_desc desc = {.logger = {.func = export_warn}};
    ak_result r = ak_io_save(out, s, &desc, &diag);
    if (r != AK_OK)
        rc = cli_fail("export", "%s: %s", diag.path[0] ? diag.path : out, diag.message[0] ? diag.message : ak_result_string(r));
    else { /* the counts `animkit info` prints: skin joints, and the nodes of the hierarchy */
        const size_t nodes = ak_scene_joint_count(s);
        size_t joints = 0;
        for (size_t j = 0; j < nodes; ++j) joints += !s->is_joint || s->is_joint[j];
        cli_wrote(out, "%zu joint%s in %zu node%s, %zu mesh%s, %zu clip%s", joints, cli_plural(joints),
                nodes, cli_plural(nodes), s->mesh_count, s->mesh_count == 1 ? "" : "es", s->clip_count,
                cli_plural(s->clip_count));
    }
    ak_scene_destroy(s);
    return rc;
}

int cmd_export(int argc, char** argv) {
    static const cli_opt opts[] = {{"--clip", "-c", true}, {"--time", "-t", true}, {"--bind", NULL, false},
                                   {"--method", "-m", true}, {"--output", "-o", true}};
    cli_args a;
    int rc = cli_parse("export", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 1) return cli_usage("export", "expected one FILE or builtin:NAME");
    const char* out = CLI_GET(&a, "--output");
    if (!out) return cli_usage("export", "missing -o OUT.obj|OUT.glb|OUT.gltf");
    if (cli_has_ext(out, ".glb") || cli_has_ext(out, ".gltf")) return export_gltf(a.pos[0], out);
    if (!cli_has_ext(out, ".obj")) return cli_usage("export", "output '%s' must end in .obj, .glb or .gltf", out);
    float t = 0.0f;
    if (CLI_GET(&a, "--time") && !cli_parse_float(CLI_GET(&a, "--time"), &t))
        return cli_usage("export", "--time '%s' is not a number", CLI_GET(&a, "--time"));
    cli_method method = CLI_LBS;
    if (CLI_GET(&a, "--method") && !cli_method_parse(CLI_GET(&a, "--method"), &method))
        return cli_usage("export", "--method must be lbs, dqs, cor, implicit or soft, not '%s'", CLI_GET(&a, "--method"));
    bool bind = CLI_GET(&a, "--bind") != NULL;

    ak_scene* s = NULL;
    if ((rc = cli_load_scene("export", a.pos[0], &s))) return rc;
    size_t vertices = 0;
    for (size_t m = 0; m < s->mesh_count; ++m) vertices += s->meshes[m].mesh ? s->meshes[m].mesh->vertex_count : 0;
    if (vertices == 0) {
        /* an empty OBJ would look like success: a BVH is a skeleton and motion only */
        rc = cli_fail("export", "%s: no mesh to export (only a skeleton and %zu clip%s; 'animkit render' draws them)", a.pos[0],
                      s->clip_count, s->clip_count == 1 ? "" : "s");
        ak_scene_destroy(s);
        return rc;
    }
    int clip = -1;
    const char* cname = CLI_GET(&a, "--clip");
    if (cname) {
        clip = ak_scene_find_clip(s, cname);
        if (clip < 0) {
            rc = cli_no_clip("export", a.pos[0], cname, s);
            ak_scene_destroy(s);
            return rc;
        }
    } else if (s->clip_count > 0) {
        clip = 0;
    }
    if (clip >= 0 && !bind) cli_time_note("export", t, s->clips[clip]);
    cli_poser p;
    if (cli_poser_init(&p, s)) {
        ak_scene_destroy(s);
        return cli_fail("export", "out of memory");
    }
    ak_result r = AK_OK;
    /* soft: simulate the flesh through the clip's frames (60 Hz) up to t */
    for (int k = 0; method == CLI_SOFT && !bind && r == AK_OK && (float)k / 60.0f < t; ++k)
        r = cli_poser_pose(&p, clip, (float)k / 60.0f, false, method);
    if (r == AK_OK) r = cli_poser_pose(&p, clip, t, bind, method);
    if (r == AK_OK) {
        ak_diag diag;
        memset(&diag, 0, sizeof diag);
        r = ak_io_write_obj(out, s, (const ak_vec3* const*)p.positions, (const ak_vec3* const*)p.normals, &diag);
        if (r != AK_OK) rc = cli_fail("export", "%s: %s", out, diag.message[0] ? diag.message : ak_result_string(r));
    } else {
        rc = cli_fail("export", "%s: cannot pose: %s", a.pos[0], ak_result_string(r));
    }
    if (!rc) cli_wrote(out, "%zu mesh%s", s->mesh_count, s->mesh_count == 1 ? "" : "es");
    cli_poser_free(&p);
    ak_scene_destroy(s);
    return rc;
}
