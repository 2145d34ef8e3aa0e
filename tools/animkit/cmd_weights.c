/* animkit weights: automatic skin weights (inverse distance or bone heat) for a model. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "outfile.h"
#include "render.h"

static const char* const usage =
    "usage: animkit weights FILE|builtin:NAME --method distance|heat [--power n]\n"
    "                       [--max-influences k] [--mesh M] [--bone NAME] -o OUT\n"
    "Compute skin weights for mesh M (default 0) from the bones of its skin (the skeleton's\n"
    "joints in bind pose): inverse distance to the bone segments, (1/d)^n normalized, or bone\n"
    "heat diffusion (Baran & Popovic 2007). Keeps the k largest influences (default 4).\n"
    "  OUT.json  {\"vertex_count\", \"influence_count\", \"joints\": [names of skin slots],\n"
    "             \"indices\": [...], \"weights\": [...]} vertex-major\n"
    "  OUT.png   with --bone, a heatmap of that bone's weights (blue 0 -> red 1) on the model;\n"
    "            without, every bone's region (the vertices it weighs most) in its own colour,\n"
    "            named in a legend\n"
    "  OUT (any other name)  the binary AKWT format documented in skin.h\n"
    "  --power   distance exponent n (default 4)\n";


static int write_json(const char* path, const ak_scene* s, const ak_scene_skin* skin, size_t vc, uint32_t k,
                      const uint16_t* joints, const float* weights) {
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "weights", path)) return CLI_BAD_INPUT;
    FILE* f = out.f;
    fprintf(f, "{\"vertex_count\": %zu, \"influence_count\": %u, \"joints\": [", vc, k);
    for (size_t q = 0; q < skin->joint_count; ++q) {
        fprintf(f, q ? ", " : "");
        cli_json_string(f, ak_skeleton_joint_name(s->skeleton, (size_t)skin->joints[q]));
    }
    fprintf(f, "],\n\"indices\": [");
    for (size_t i = 0; i < vc * k; ++i) fprintf(f, "%s%u", i ? "," : "", joints[i]);
    fprintf(f, "],\n\"weights\": [");
    for (size_t i = 0; i < vc * k; ++i) fprintf(f, "%s%.7g", i ? "," : "", (double)weights[i]);
    fprintf(f, "]}\n");
    return cli_outfile_commit(&out, "weights");
}

int cmd_weights(int argc, char** argv) {
    static const cli_opt opts[] = {{"--method", "-m", true},     {"--power", NULL, true}, {"--max-influences", "-k", true},
                                   {"--mesh", NULL, true},       {"--bone", NULL, true},  {"--output", "-o", true}};
    cli_args a;
    int rc = cli_parse("weights", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 1) return cli_usage("weights", "expected one FILE or builtin:NAME");
    const char* method = CLI_GET(&a, "--method");
    if (!method) return cli_usage("weights", "missing --method distance|heat");
    ak_weights_method wm;
    if (strcmp(method, "distance") == 0) wm = AK_WEIGHTS_DISTANCE;
    else if (strcmp(method, "heat") == 0) wm = AK_WEIGHTS_HEAT;
    else return cli_usage("weights", "--method must be distance or heat, not '%s'", method);
    float power = 0.0f;
    if (CLI_GET(&a, "--power") && (!cli_parse_float(CLI_GET(&a, "--power"), &power) || power <= 0.0f))
        return cli_usage("weights", "--power '%s' is not a number > 0", CLI_GET(&a, "--power"));
    long k = 4, mesh_index = 0;
    if (CLI_GET(&a, "--max-influences") && !cli_parse_int(CLI_GET(&a, "--max-influences"), 1, AK_MAX_INFLUENCES, &k))
        return cli_usage("weights", "--max-influences '%s' is not a whole number in 1..%d", CLI_GET(&a, "--max-influences"),
                         AK_MAX_INFLUENCES);
    if (CLI_GET(&a, "--mesh") && !cli_parse_int(CLI_GET(&a, "--mesh"), 0, 1000000, &mesh_index))
        return cli_usage("weights", "--mesh '%s' is not a mesh index", CLI_GET(&a, "--mesh"));
    const char* out = CLI_GET(&a, "--output");
    if (!out) return cli_usage("weights", "missing -o OUT");
    bool png = cli_has_ext(out, ".png");

    ak_scene* s = NULL;
    if ((rc = cli_load_scene("weights", a.pos[0], &s))) return rc;
    uint16_t* joints = NULL;
    float* weights = NULL;
    ak_skin_bone* bones = NULL;
    if ((size_t)mesh_index >= s->mesh_count) {
        rc = cli_fail("weights", "%s: no mesh %ld (%zu mesh%s)", a.pos[0], mesh_index, s->mesh_count,
                      s->mesh_count == 1 ? "" : "es");
        goto done;
    }
    const ak_scene_mesh* sm = &s->meshes[mesh_index];
    if (sm->skin < 0 || !s->skeleton) {
        rc = cli_fail("weights", "%s: mesh %ld has no skin, so no bones to weight against", a.pos[0], mesh_index);
        goto done;
    }
    const ak_scene_skin* skin = &s->skins[sm->skin];
    int slot = 0;
    const char* bone_name = CLI_GET(&a, "--bone");
    if (bone_name) {
        int j = ak_skeleton_find_joint(s->skeleton, bone_name);
        slot = -1;
        for (size_t q = 0; j >= 0 && q < skin->joint_count; ++q)
            if (skin->joints[q] == j) slot = (int)q;
        if (slot < 0) {
            rc = cli_fail("weights", "%s: no joint named '%s' in the skin", a.pos[0], bone_name);
            goto done;
        }
    }
    const ak_mesh* mesh = sm->mesh;
    size_t vc = mesh->vertex_count;
    joints = calloc(vc * (size_t)k, sizeof(uint16_t));
    weights = calloc(vc * (size_t)k, sizeof(float));
    bones = calloc(2 * skin->joint_count + 1, sizeof(ak_skin_bone));
    if (!joints || !weights || !bones) {
        rc = cli_fail("weights", "out of memory");
        goto done;
    }
    size_t bone_count = cli_skin_bones(s, skin, bones);
    ak_weights_desc d = {
        .method = wm,
        .positions = {mesh->positions, vc},
        .indices = {mesh->indices, mesh->triangle_count * 3},
        .bones = {bones, bone_count},
        .max_influences = (uint32_t)k,
        .distance_power = power,
    };
    double t0 = cli_now();
    ak_result r = ak_skin_weights_compute(&d, NULL, (ak_u16_span){joints, vc * (size_t)k}, (ak_f32_span){weights, vc * (size_t)k});
    double dt = cli_now() - t0;
    if (r != AK_OK) {
        rc = cli_fail("weights", "%s: %s", a.pos[0], ak_result_string(r));
        goto done;
    }
    if (png && bone_name) {
        rc = cli_render_weights_png(out, s, (size_t)mesh_index, joints, weights, (uint32_t)k, slot, bone_name);
    } else if (png) {
        const char** names = calloc(skin->joint_count + 1, sizeof(char*));
        if (!names) {
            rc = cli_fail("weights", "out of memory");
            goto done;
        }
        for (size_t q = 0; q < skin->joint_count; ++q) names[q] = ak_skeleton_joint_name(s->skeleton, (size_t)skin->joints[q]);
        rc = cli_render_bones_png(out, s, (size_t)mesh_index, joints, weights, (uint32_t)k, skin->joint_count, names);
        free(names);
        if (rc == CLI_OK)
            fprintf(stderr, "%s: no --bone: each bone's dominant region in its own colour, named in the legend "
                            "(--bone NAME shows one bone's weights as a heatmap)\n", out);
    } else if (cli_has_ext(out, ".json")) {
        rc = write_json(out, s, skin, vc, (uint32_t)k, joints, weights);
    } else {
        r = ak_skin_weights_write_file(out, (ak_u16_cspan){joints, vc * (size_t)k}, (ak_f32_cspan){weights, vc * (size_t)k},
                                       vc, (uint32_t)k);
        if (r != AK_OK) rc = cli_fail("weights", "%s: %s", out, ak_result_string(r));
    }
    if (rc == CLI_OK)
        cli_wrote(out, "%s weights, %zu vert%s, %zu bone%s, %u influence%s, %.3f s", method, vc,
                vc == 1 ? "ex" : "ices", bone_count, cli_plural(bone_count), (unsigned)k, cli_plural((size_t)k), dt);
done:
    free(joints);
    free(weights);
    free(bones);
    ak_scene_destroy(s);
    return rc;
}
