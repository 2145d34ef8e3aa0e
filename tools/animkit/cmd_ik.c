/* animkit ik: solve a joint chain of a model so its effector reaches a target. */
#include <stdlib.h>
#include <math.h>
#include <string.h>

#include "cli.h"
#include "render.h"

static const char* const usage =
    "usage: animkit ik FILE|builtin:NAME --effector JOINT --target X,Y,Z [--root JOINT]\n"
    "                  [--solver ccd|fabrik|twobone|dls] [--iterations N] [--tolerance E]\n"
    "                  [--clip C --time T] [--json] [-o OUT.obj|OUT.png]\n"
    "Solve on the model's pose (bind pose, or clip C at time T) so JOINT reaches the world-space\n"
    "target, honouring joint types and limits. Prints reached, error, iterations and time.\n"
    "  --root       first joint of the chain. Default: the effector's grandparent for twobone;\n"
    "               else the limb: up from the effector through skin joints (every node when\n"
    "               no skin), stopping below the first joint with several child joints (the\n"
    "               chest for an arm, the pelvis for a leg) or at the topmost joint; plain\n"
    "               nodes above the skeleton (e.g. a Z_UP node) never join. The chain used\n"
    "               is printed\n"
    "  --solver     default fabrik\n"
    "  --iterations iteration budget, 1 to 1000000 (default 50)\n"
    "  --tolerance  distance counted as reached, model units (default 1e-4 x chain length)\n"
    "  --json       one JSON object: reached, error, iterations, time_ms, solver, joints (the\n"
    "               chain root..effector after solving: [{name, position [x,y,z]}]) and\n"
    "               initial (the same chain before solving). Numbers are finite; a value that\n"
    "               is not (NaN, infinity) is written null\n"
    "  -o           write the posed meshes (.obj) or a rendered image of the chain and target (.png)\n";

static int find_joint(const ak_scene* s, const char* name) {
    return s->skeleton ? ak_skeleton_find_joint(s->skeleton, name) : -1;
}

static void print_chain_json(const ak_scene* s, const int16_t* chain, const ak_vec3* pos, size_t n) {
    printf("[");
    for (size_t i = 0; i < n; ++i) {
        printf(i ? ", {\"name\": " : "{\"name\": ");
        cli_json_string(stdout, ak_skeleton_joint_name(s->skeleton, (size_t)chain[i]));
        printf(", \"position\": [");
        cli_json_write_number(stdout, (double)pos[i].x);
        printf(", ");
        cli_json_write_number(stdout, (double)pos[i].y);
        printf(", ");
        cli_json_write_number(stdout, (double)pos[i].z);
        printf("]}");
    }
    printf("]");
}

static bool is_joint(const ak_scene* s, bool all, int j) { return all || !s->is_joint || s->is_joint[j]; }

/* The default chain root for the iterative solvers: the limb the effector ends. Walk up from
 * the effector through joints (nodes a skin uses), stopping below the first ancestor with
 * more than one child joint (the chest for an arm, the pelvis for a leg) once the chain has
 * two joints, and at the topmost joint. Plain nodes above the skeleton never join (unless
 * the effector is itself a plain node: then every node counts as a joint). */
static int default_root(const ak_scene* s, int eff) {
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    const bool all = !is_joint(s, false, eff); /* an effector no skin uses: every node counts */
    size_t size = 1;
    int root = eff;
    for (;;) {
        const int p = parents.ptr[root];
        if (p < 0 || !is_joint(s, all, p)) break;
        if (size >= 2) {
            size_t kids = 0;
            for (size_t j = (size_t)p + 1; j < parents.count && kids < 2; ++j)
                if (parents.ptr[j] == p && is_joint(s, all, (int)j)) ++kids;
            if (kids > 1) break;
        }
        root = p;
        ++size;
    }
    return root;
}


int cmd_ik(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--effector", "-e", true}, {"--target", NULL, true}, {"--root", NULL, true},  {"--solver", "-s", true},
        {"--iterations", NULL, true}, {"--tolerance", NULL, true}, {"--clip", "-c", true}, {"--time", "-t", true},
        {"--json", NULL, false},    {"--output", "-o", true},
    };
    cli_args a;
    int rc = cli_parse("ik", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 1) return cli_usage("ik", "expected one FILE or builtin:NAME");
    const char* eff_name = CLI_GET(&a, "--effector");
    if (!eff_name) return cli_usage("ik", "missing --effector JOINT");
    ak_vec3 target;
    if (!CLI_GET(&a, "--target")) return cli_usage("ik", "missing --target X,Y,Z");
    if (!cli_parse_vec3(CLI_GET(&a, "--target"), &target))
        return cli_usage("ik", "--target '%s' is not three numbers X,Y,Z", CLI_GET(&a, "--target"));
    /* The library solves at any scale and reports the error in double, saturated at FLT_MAX
     * (3.4e38): within +-1e37 every distance to the model is far below that. */
    if (!(fabsf(target.x) <= 1e37f && fabsf(target.y) <= 1e37f && fabsf(target.z) <= 1e37f))
        return cli_usage("ik", "--target '%s' is outside +-1e37", CLI_GET(&a, "--target"));
    ak_ik_solver solver = AK_IK_SOLVER_FABRIK;
    if (CLI_GET(&a, "--solver") && ak_ik_solver_parse(CLI_GET(&a, "--solver"), &solver) != AK_OK)
        return cli_usage("ik", "--solver must be ccd, fabrik, twobone or dls, not '%s'", CLI_GET(&a, "--solver"));
    long iterations = 0;
    if (CLI_GET(&a, "--iterations") && !cli_parse_int(CLI_GET(&a, "--iterations"), 1, 1000000, &iterations))
        return cli_usage("ik", "--iterations '%s' is not a whole number in 1..1000000", CLI_GET(&a, "--iterations"));
    float tolerance = 0.0f, t = 0.0f;
    if (CLI_GET(&a, "--tolerance") && (!cli_parse_float(CLI_GET(&a, "--tolerance"), &tolerance) || tolerance < 0))
        return cli_usage("ik", "--tolerance '%s' is not a number >= 0", CLI_GET(&a, "--tolerance"));
    if (CLI_GET(&a, "--time") && !cli_parse_float(CLI_GET(&a, "--time"), &t))
        return cli_usage("ik", "--time '%s' is not a number", CLI_GET(&a, "--time"));
    const char* out = CLI_GET(&a, "--output");
    if (out && !cli_has_ext(out, ".obj") && !cli_has_ext(out, ".png"))
        return cli_usage("ik", "output '%s' must end in .obj or .png", out);
    bool json = CLI_GET(&a, "--json") != NULL;

    ak_scene* s = NULL;
    if ((rc = cli_load_scene("ik", a.pos[0], &s))) return rc;
    cli_poser p;
    int16_t* chain = NULL;
    ak_vec3 *before = NULL, *after = NULL;
    uint8_t* scratch = NULL;
    memset(&p, 0, sizeof p);
    int eff = find_joint(s, eff_name);
    if (eff < 0) {
        rc = cli_fail("ik", "%s: no joint named '%s'", a.pos[0], eff_name);
        goto done;
    }
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    int root = -1;
    if (CLI_GET(&a, "--root")) {
        root = find_joint(s, CLI_GET(&a, "--root"));
        if (root < 0) {
            rc = cli_fail("ik", "%s: no joint named '%s'", a.pos[0], CLI_GET(&a, "--root"));
            goto done;
        }
    } else if (solver == AK_IK_SOLVER_TWO_BONE) {
        root = eff;
        for (int k = 0; k < 2 && parents.ptr[root] >= 0; ++k) root = parents.ptr[root];
    } else {
        root = default_root(s, eff);
    }
    int clip = -1;
    if (CLI_GET(&a, "--clip")) {
        clip = ak_scene_find_clip(s, CLI_GET(&a, "--clip"));
        if (clip < 0) {
            rc = cli_no_clip("ik", a.pos[0], CLI_GET(&a, "--clip"), s);
            goto done;
        }
    }
    if (clip >= 0) cli_time_note("ik", t, s->clips[clip]);
    size_t n = ak_scene_joint_count(s), chain_count = 0;
    chain = calloc(n, sizeof(int16_t));
    before = calloc(n, sizeof(ak_vec3));
    after = calloc(n, sizeof(ak_vec3));
    if (!chain || !before || !after || cli_poser_init(&p, s)) {
        rc = cli_fail("ik", "out of memory");
        goto done;
    }
    ak_result r = ak_ik_chain_build(s->skeleton, root, eff, (ak_i16_span){chain, n}, &chain_count);
    if (r == AK_ERR_NOT_FOUND) {
        rc = cli_fail("ik", "%s: joint '%s' is not an ancestor of '%s'", a.pos[0], CLI_GET(&a, "--root"), eff_name);
        goto done;
    }
    if (r == AK_OK && solver == AK_IK_SOLVER_TWO_BONE && chain_count != 3) {
        rc = cli_fail("ik", "%s: twobone needs a chain of 3 joints, '%s'..'%s' has %zu", a.pos[0],
                      ak_skeleton_joint_name(s->skeleton, (size_t)root), eff_name, chain_count);
        goto done;
    }
    if (r == AK_OK) r = cli_poser_sample(&p, clip, t, clip < 0);
    ak_transform_span pose = {p.local, n};
    ak_i16_cspan ch = {chain, chain_count};
    if (r == AK_OK) r = ak_ik_chain_positions(s->skeleton, (ak_transform_cspan){p.local, n}, ch, (ak_vec3_span){before, n});
    size_t ss = ak_ik_chain_scratch_size(solver, chain_count);
    scratch = malloc(ss);
    bool reached = false;
    float error = 0.0f;
    size_t used = 0;
    double t0 = cli_now(), elapsed = 0.0;
    if (r == AK_OK) {
        ak_ik_chain_job job = {
            .skeleton = s->skeleton, .pose = pose, .chain = ch, .target = target, .solver = solver,
            .max_iterations = (size_t)iterations, .tolerance = tolerance,
            .scratch = {scratch, ss}, .out_reached = &reached, .out_error = &error, .out_iterations = &used,
        };
        r = ak_ik_chain_run(&job);
        elapsed = cli_now() - t0;
    }
    if (r == AK_OK) r = ak_ik_chain_positions(s->skeleton, (ak_transform_cspan){p.local, n}, ch, (ak_vec3_span){after, n});
    if (r != AK_OK) {
        rc = cli_fail("ik", "%s: %s", a.pos[0], ak_result_string(r));
        goto done;
    }
    if (json) {
        printf("{\"reached\": %s, \"error\": ", reached ? "true" : "false");
        cli_json_write_number(stdout, (double)error);
        printf(", \"iterations\": %zu, \"time_ms\": ", used);
        cli_json_write_number(stdout, elapsed * 1e3);
        printf(", \"solver\": \"%s\", \"joints\": ", ak_ik_solver_name(solver));
        print_chain_json(s, chain, after, chain_count);
        printf(", \"initial\": ");
        print_chain_json(s, chain, before, chain_count);
        printf("}\n");
    } else {
        printf("solver %s, chain (%zu joint%s%s):", ak_ik_solver_name(solver), chain_count, chain_count == 1 ? "" : "s",
               CLI_GET(&a, "--root") ? "" : ", default root; --root to change");
        for (size_t i = 0; i < chain_count; ++i) {
            char name[512];
            cli_escape(name, sizeof name, ak_skeleton_joint_name(s->skeleton, (size_t)chain[i]));
            printf("%s %s", i ? " ->" : "", name);
        }
        printf("\n");
        printf("reached %s, error %.6g, iterations %zu, time %.3f ms\n", reached ? "yes" : "no", (double)error, used,
               elapsed * 1e3);
        for (size_t i = 0; i < chain_count; ++i)
            printf("  %-20s (%9.5g %9.5g %9.5g) -> (%9.5g %9.5g %9.5g)\n",
                   ak_skeleton_joint_name(s->skeleton, (size_t)chain[i]), (double)before[i].x, (double)before[i].y,
                   (double)before[i].z, (double)after[i].x, (double)after[i].y, (double)after[i].z);
    }
    if (out) {
        if ((r = cli_poser_deform(&p, false, CLI_LBS)) != AK_OK) {
            rc = cli_fail("ik", "%s: cannot pose: %s", a.pos[0], ak_result_string(r));
        } else if (cli_has_ext(out, ".obj")) {
            ak_diag diag;
            memset(&diag, 0, sizeof diag);
            r = ak_io_write_obj(out, s, (const ak_vec3* const*)p.positions, (const ak_vec3* const*)p.normals, &diag);
            if (r != AK_OK) rc = cli_fail("ik", "%s: %s", out, diag.message[0] ? diag.message : ak_result_string(r));
        } else {
            rc = cli_render_ik_png(out, &p, chain, chain_count, target);
        }
        if (rc == CLI_OK) cli_wrote(out, "the solved pose");
    }
done:
    free(scratch);
    free(chain);
    free(before);
    free(after);
    cli_poser_free(&p);
    ak_scene_destroy(s);
    return rc;
}
