/* animkit info: skeleton tree, meshes and clips of a model, as text or JSON. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char* const usage =
    "usage: animkit info FILE|builtin:NAME [--json]\n"
    "Print the skeleton tree (names, parents, joint types), the meshes (vertices, triangles,\n"
    "skinned or not, influences per vertex, morph targets) and the clips (name, duration,\n"
    "channel count).\n"
    "  --json   one JSON object: {\"joints\": [{name, parent, type}], \"meshes\": [{name,\n"
    "           vertices, triangles, skinned, influences, morph_targets}], \"clips\": [{name,\n"
    "           duration, channels}], \"nodes\": N}. \"joints\" lists the skin joints (every\n"
    "           node when the file has no skin); parent is the index in that list of the\n"
    "           nearest listed ancestor, -1 for a root.\n";

static const char* joint_type_name(ak_joint_type t) {
    switch (t) {
    case AK_JOINT_BALL: return "ball";
    case AK_JOINT_HINGE: return "hinge";
    case AK_JOINT_PRISM: return "prism";
    default: return "free";
    }
}

/* Indices of the listed joints and, per listed joint, its listed parent. */
static size_t list_joints(const ak_scene* s, int* out_list, int* out_parent, int* node_to_list) {
    size_t n = ak_scene_joint_count(s), count = 0;
    if (n == 0) return 0;
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    for (size_t j = 0; j < n; ++j) {
        node_to_list[j] = -1;
        if (s->is_joint && !s->is_joint[j]) continue;
        int p = parents.ptr[j];
        while (p >= 0 && node_to_list[p] < 0) p = parents.ptr[p];
        node_to_list[j] = (int)count;
        out_list[count] = (int)j;
        out_parent[count] = p >= 0 ? node_to_list[p] : -1;
        ++count;
    }
    return count;
}

static void print_tree(const ak_scene* s, const int* list, const int* parent, size_t count, int root, int depth) {
    for (size_t i = 0; i < count; ++i) {
        if (parent[i] != root) continue;
        int j = list[i];
        char name[512];
        cli_escape(name, sizeof name, ak_skeleton_joint_name(s->skeleton, (size_t)j));
        printf("  %*s%s (%s)\n", depth * 2, "", name,
               joint_type_name(ak_skeleton_joint_type(s->skeleton, (size_t)j)));
        print_tree(s, list, parent, count, (int)i, depth + 1);
    }
}

int cmd_info(int argc, char** argv) {
    static const cli_opt opts[] = {{"--json", NULL, false}};
    cli_args a;
    int rc = cli_parse("info", argc, argv, opts, 1, &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 1) return cli_usage("info", "expected one FILE or builtin:NAME");
    ak_scene* s = NULL;
    if ((rc = cli_load_scene("info", a.pos[0], &s))) return rc;
    if (cli_has_ext(a.pos[0], ".obj")) cli_obj_rig_note("info", a.pos[0]);
    size_t n = ak_scene_joint_count(s);
    int* list = calloc(n + 1, sizeof(int));
    int* parent = calloc(n + 1, sizeof(int));
    int* map = calloc(n + 1, sizeof(int));
    if (!list || !parent || !map) {
        free(list), free(parent), free(map), ak_scene_destroy(s);
        return cli_fail("info", "out of memory");
    }
    size_t count = list_joints(s, list, parent, map);
    bool json = CLI_GET(&a, "--json") != NULL;
    if (json) {
        printf("{\"name\": ");
        cli_json_string(stdout, s->name);
        printf(", \"nodes\": %zu, \"joints\": [", n);
        for (size_t i = 0; i < count; ++i) {
            printf(i ? ", " : "");
            printf("{\"name\": ");
            cli_json_string(stdout, ak_skeleton_joint_name(s->skeleton, (size_t)list[i]));
            printf(", \"parent\": %d, \"type\": \"%s\"}", parent[i],
                   joint_type_name(ak_skeleton_joint_type(s->skeleton, (size_t)list[i])));
        }
        printf("], \"meshes\": [");
        for (size_t m = 0; m < s->mesh_count; ++m) {
            const ak_mesh* mesh = s->meshes[m].mesh;
            printf(m ? ", " : "");
            printf("{\"name\": ");
            cli_json_string(stdout, mesh->name);
            printf(", \"vertices\": %zu, \"triangles\": %zu, \"skinned\": %s, \"influences\": %u, "
                   "\"morph_targets\": %zu}",
                   mesh->vertex_count, mesh->triangle_count,
                   (s->meshes[m].skin >= 0 && mesh->influence_count > 0) ? "true" : "false", mesh->influence_count,
                   mesh->morph_target_count);
        }
        printf("], \"clips\": [");
        for (size_t c = 0; c < s->clip_count; ++c) {
            printf(c ? ", " : "");
            printf("{\"name\": ");
            cli_json_string(stdout, ak_clip_name(s->clips[c]));
            printf(", \"duration\": %.9g, \"channels\": %zu}", (double)ak_clip_duration(s->clips[c]),
                   cli_clip_file_channel_count(s, s->clips[c]));
        }
        printf("]}\n");
    } else {
        char text[512];
        cli_escape(text, sizeof text, s->name);
        printf("%s\n", text);
        printf("skeleton: %zu joint%s in %zu node%s (joints: the skin's; nodes: the whole hierarchy)\n", count,
               cli_plural(count), n, cli_plural(n));
        print_tree(s, list, parent, count, -1, 0);
        printf("meshes: %zu\n", s->mesh_count);
        for (size_t m = 0; m < s->mesh_count; ++m) {
            const ak_mesh* mesh = s->meshes[m].mesh;
            cli_escape(text, sizeof text, mesh->name[0] ? mesh->name : "(unnamed)");
            printf("  %-24s %7zu vertices %7zu triangles  ", text,
                   mesh->vertex_count, mesh->triangle_count);
            if (s->meshes[m].skin >= 0 && mesh->influence_count > 0)
                printf("skinned (%u influence%s/vertex)", mesh->influence_count, mesh->influence_count == 1 ? "" : "s");
            else
                printf("not skinned");
            if (mesh->morph_target_count) printf(", %zu morph targets", mesh->morph_target_count);
            printf("\n");
        }
        printf("clips: %zu\n", s->clip_count);
        for (size_t c = 0; c < s->clip_count; ++c) {
            size_t nch = cli_clip_file_channel_count(s, s->clips[c]);
            cli_escape(text, sizeof text, ak_clip_name(s->clips[c])[0] ? ak_clip_name(s->clips[c]) : "(unnamed)");
            printf("  %-24s %8.4f s  %zu channel%s\n", text,
                   (double)ak_clip_duration(s->clips[c]), nch, nch == 1 ? "" : "s");
        }
    }
    free(list);
    free(parent);
    free(map);
    ak_scene_destroy(s);
    return CLI_OK;
}
