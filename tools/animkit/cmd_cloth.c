/* animkit cloth: simulate a cloth scene or preset; write JSON, OBJ, PNG or GIF. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"
#include "cloth_run.h"
#include "outfile.h"
#include "sim_bake.h"

static const char* const usage =
    "usage: animkit cloth [SCENE.json | --preset flag|curtain|drape|cape] [--solver springs|implicit|xpbd]\n"
    "                     [--steps N] [--dt DT] [--substeps S] [--threads T] [--json OUT.json]\n"
    "                     [-o OUT.gif|OUT.png|OUT.obj|OUT.glb|OUT.gltf]\n"
    "Simulate a cloth: a flag in gusty wind, a curtain on rings, a square draped on a sphere, or a\n"
    "cape on builtin:humanoid walking; or the scene a JSON file describes (docs/cloth.md lists\n"
    "every key). The solver is XPBD (compliant constraints, substeps), the classic mass-spring\n"
    "model (semi-implicit Euler, run at the substep count its stiffest springs need unless\n"
    "--substeps is given), or the same springs under implicit Euler (Baraff-Witkin, stable at any step).\n"
    "--json writes {\"time\", \"positions\", \"max_stretch\", \"energy\"} of the final state;\n"
    "-o renders the run (GIF), its last frame (PNG), writes the last state as OBJ, or the whole run\n"
    "as glTF (.glb, or .gltf + .bin): morph-target animation of the cloth (docs/io.md).\n"
    "Exit status: 0 success, 1 bad scene or a blow-up (named by its step), 2 bad usage.\n";

/* by ak_cloth_solver */
static const char* const solver_names[AK_CLOTH_SOLVER_COUNT] = {"xpbd", "springs", "pbd", "implicit"};
static const char* const solver_long[AK_CLOTH_SOLVER_COUNT] = {"XPBD", "mass-spring", "PBD", "implicit Euler"};

/* ---- output ------------------------------------------------------------------------------ */

static int write_json(const char* path, float time, const ak_vec3* x, size_t n, float stretch, double energy) {
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "cloth", path)) return CLI_BAD_INPUT;
    FILE* f = out.f;
    fprintf(f, "{\"time\": %.9g, \"positions\": [", (double)time);
    for (size_t v = 0; v < n; ++v)
        fprintf(f, "%s[%.9g, %.9g, %.9g]", v ? ", " : "", (double)x[v].x, (double)x[v].y, (double)x[v].z);
    fprintf(f, "], \"max_stretch\": %.9g, \"energy\": %.9g}\n", (double)stretch, energy);
    return cli_outfile_commit(&out, "cloth");
}

static int write_obj(const char* path, const ak_cloth* cloth, const ak_vec3* x, const ak_vec3* nrm) {
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "cloth", path)) return CLI_BAD_INPUT;
    FILE* f = out.f;
    const size_t n = ak_cloth_vertex_count(cloth);
    ak_u32_cspan idx = ak_cloth_indices(cloth);
    fprintf(f, "# animkit cloth: %zu vertices, %zu triangles\no cloth\n", n, idx.count / 3);
    for (size_t v = 0; v < n; ++v) fprintf(f, "v %.7g %.7g %.7g\n", (double)x[v].x, (double)x[v].y, (double)x[v].z);
    for (size_t v = 0; v < n; ++v) fprintf(f, "vn %.6g %.6g %.6g\n", (double)nrm[v].x, (double)nrm[v].y, (double)nrm[v].z);
    for (size_t t = 0; t + 2 < idx.count; t += 3)
        fprintf(f, "f %u//%u %u//%u %u//%u\n", idx.ptr[t] + 1, idx.ptr[t] + 1, idx.ptr[t + 1] + 1, idx.ptr[t + 1] + 1,
                idx.ptr[t + 2] + 1, idx.ptr[t + 2] + 1);
    return cli_outfile_commit(&out, "cloth");
}

/* ---- the command -------------------------------------------------------------------------- */

int cmd_cloth(int argc, char** argv) {
    static const cli_opt opts[] = {{"--preset", NULL, true}, {"--solver", NULL, true},   {"--steps", NULL, true},
                                   {"--dt", NULL, true},     {"--substeps", NULL, true}, {"--threads", NULL, true},
                                   {"--json", NULL, true},   {"--output", "-o", true}};
    cli_args a;
    int rc = cli_parse("cloth", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    const char* preset = CLI_GET(&a, "--preset");
    if (a.pos_count > 1) return cli_usage("cloth", "expected at most one SCENE.json");
    if ((a.pos_count == 1) == (preset != NULL)) return cli_usage("cloth", "give either SCENE.json or --preset NAME");
    const char* out = CLI_GET(&a, "--output");
    const char* json = CLI_GET(&a, "--json");
    if (out && !cli_has_ext(out, ".gif") && !cli_has_ext(out, ".png") && !cli_has_ext(out, ".obj") && !sim_bake_wanted(out))
        return cli_usage("cloth", "output '%s' must end in .gif, .png, .obj, .glb or .gltf", out);
    ak_cloth_scene sc;
    const char* name = preset ? preset : a.pos[0];
    ak_diag diag;
    if (preset) {
        const ak_result res = ak_cloth_scene_preset(preset, &sc, &diag);
        if (res == AK_ERR_NOT_FOUND) return cli_usage("cloth", "unknown preset '%s' (flag, curtain, drape, cape)", preset);
        if (res != AK_OK) return cli_fail("cloth", "%s", diag.message);
    } else if (ak_cloth_scene_load_file(a.pos[0], &sc, &diag) != AK_OK) {
        return cli_fail("cloth", "%s", diag.message);
    }
    /* command-line overrides */
    const char* v;
    long lv;
    if ((v = CLI_GET(&a, "--solver"))) {
        if (strcmp(v, "xpbd") == 0) sc.desc.solver = AK_CLOTH_XPBD;
        else if (strcmp(v, "springs") == 0) sc.desc.solver = AK_CLOTH_SPRINGS;
        else if (strcmp(v, "implicit") == 0) sc.desc.solver = AK_CLOTH_IMPLICIT;
        else rc = cli_usage("cloth", "--solver must be springs, implicit or xpbd, not '%s'", v);
        if ((sc.desc.solver == AK_CLOTH_SPRINGS || sc.desc.solver == AK_CLOTH_IMPLICIT) &&
            (sc.desc.bending == AK_CLOTH_BEND_DIHEDRAL || sc.desc.bending == AK_CLOTH_BEND_ISOMETRIC))
            sc.desc.bending = AK_CLOTH_BEND_SPRINGS;
    }
    if (!rc && (v = CLI_GET(&a, "--steps"))) {
        if (!cli_parse_int(v, 0, AK_CLOTH_SCENE_MAX_STEPS, &lv)) rc = cli_usage("cloth", "--steps must be 0..%ld", AK_CLOTH_SCENE_MAX_STEPS);
        else sc.steps = lv;
    }
    if (!rc && (v = CLI_GET(&a, "--dt"))) {
        float dt;
        if (!cli_parse_float(v, &dt) || !(dt >= 1e-7f) || dt > 1.0f) rc = cli_usage("cloth", "--dt must be in [1e-07, 1] seconds");
        else sc.dt = dt;
    }
    if (!rc && (v = CLI_GET(&a, "--substeps"))) {
        if (!cli_parse_int(v, 1, 10000, &lv)) rc = cli_usage("cloth", "--substeps must be 1..10000");
        else sc.substeps = (uint32_t)lv, sc.substeps_forced = true;
    }
    if (!rc && (v = CLI_GET(&a, "--threads"))) {
        if (!cli_parse_int(v, 1, 64, &lv)) rc = cli_usage("cloth", "--threads must be 1..64");
        else sc.thread_count = (int)lv;
    }
    if (rc) {
        ak_cloth_scene_free(&sc);
        return rc;
    }

    cloth_run run;
    ak_result r = AK_OK;
    cli_frame frame;
    memset(&frame, 0, sizeof frame);
    ak_image img = {0};
    ak_gif_writer* gw = NULL;
    sim_bake bake;
    memset(&bake, 0, sizeof bake);

    memset(&run, 0, sizeof run);
    rc = cloth_run_init(&run, &sc, "cloth", name); /* (the spring solver's substeps are known after it) */
    if (!rc) rc = cli_work_check("cloth",
                        (double)sc.desc.grid_width * (double)sc.desc.grid_height * (double)sc.steps *
                            (double)sc.substeps * (double)sc.iterations,
                        "particle updates (particles x steps x substeps x iterations)",
                        "--steps, --substeps, the scene's \"iterations\" or the grid size");
    if (rc) goto done;
    if (sim_bake_wanted(out) && (rc = sim_bake_mesh_init(&bake, "cloth", out, run.n, sc.steps))) goto done;
    cloth_character* const ch = &run.ch;
    ak_cloth* const cloth = run.cloth;
    ak_vec3* const x = run.x;
    ak_vec3* const vel = run.vel;
    ak_vec3* const nrm = run.nrm;
    const size_t n = run.n;

    /* rendering: a camera framed on the cloth, the colliders and the character at rest */
    const bool gif = out && cli_has_ext(out, ".gif"), png = out && cli_has_ext(out, ".png");
    cloth_prop* props = NULL;
    size_t prop_count = 0;
    if (gif || png) {
        ak_vec3 lo, hi;
        cloth_run_bounds(&run, &lo, &hi);
        /* a character faces +Z: look from behind and to its left, where a cape hangs and the
         * key light (from the front left) still grazes it */
        if (cli_frame_init(&frame, ch->scene, 480, 360, lo, hi, ch->scene ? 2.5f : 0.6f) || cli_image_alloc(&img, 480, 360)) {
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        prop_count = sc.sphere_count + sc.capsule_count;
        if (prop_count > CLI_MAX_EXTRA - 1) prop_count = CLI_MAX_EXTRA - 1;
        props = calloc(prop_count + 1, sizeof(cloth_prop));
        if (!props) {
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        for (size_t k = 0; k < prop_count; ++k) {
            if (k < sc.sphere_count) cloth_prop_build(&props[k], sc.spheres[k].center, sc.spheres[k].center, sc.spheres[k].radius);
            else {
                const ak_cloth_capsule* cp = &sc.capsules[k - sc.sphere_count];
                cloth_prop_build(&props[k], cp->a, cp->b, cp->radius);
            }
        }
        if (gif && ak_gif_writer_create(out, &(ak_gif_desc){.width = 480, .height = 360, .delay_cs = 4}, NULL, &gw) != AK_OK) {
            free(props);
            rc = cli_fail("cloth", "%s: cannot create the file", out);
            goto done;
        }
    }

    const double t0 = cli_now();
    int frames = 0;
    float time = 0.0f;
    for (long step = 0; step <= sc.steps; ++step) {
        /* draw the state at `time` (25 frames per second of simulated time) */
        if ((gif && (step == 0 || floorf(time * 25.0f) != floorf((time - sc.dt) * 25.0f))) || (png && step == sc.steps)) {
            ak_raster_mesh extra[CLI_MAX_EXTRA];
            size_t ne = 0;
            ak_u32_cspan idx = ak_cloth_indices(cloth);
            extra[ne++] = (ak_raster_mesh){.positions = {x, n}, .normals = {nrm, n}, .indices = idx,
                                           .material = {.color = {0.72f, 0.16f, 0.18f, 1}, .specular = 0.1f}};
            for (size_t k = 0; k < prop_count; ++k)
                extra[ne++] = (ak_raster_mesh){.positions = {props[k].pos, PROP_VERTS}, .normals = {props[k].nrm, PROP_VERTS},
                                               .indices = {props[k].idx, PROP_TRIS * 3},
                                               .material = {.color = {0.55f, 0.62f, 0.72f, 1}}};
            char title[160];
            snprintf(title, sizeof title, "cloth %s  %s  t=%.2fs", preset ? preset : "", solver_names[sc.desc.solver < AK_CLOTH_SOLVER_COUNT ? sc.desc.solver : 0], (double)time);
            cli_draw_opts o = {.title = title, .extra = extra, .extra_count = ne};
            r = cli_frame_draw(&frame, ch->scene ? &ch->poser : NULL, &o, &img);
            if (r == AK_OK) r = gif ? ak_gif_writer_add_frame(gw, &img) : ak_png_write(out, &img);
            if (r != AK_OK) {
                free(props);
                rc = cli_fail("cloth", "%s: cannot render or write: %s", out, ak_result_string(r));
                goto done;
            }
            ++frames;
        }
        if (bake.cap) sim_bake_mesh_add(&bake, step, x, nrm);
        if (step == sc.steps) break;
        if ((rc = cloth_run_step(&run, "cloth", name))) {
            free(props);
            goto done;
        }
        time = run.time;
        cli_progress("cloth", (size_t)step + 1, (size_t)sc.steps);
    }
    const double elapsed = cli_now() - t0;
    free(props);
    if (gw) {
        r = ak_gif_writer_finish(gw);
        gw = NULL;
        if (r != AK_OK) {
            rc = cli_fail("cloth", "%s: cannot write: %s", out, ak_result_string(r));
            goto done;
        }
    }
    const float stretch = ak_cloth_max_stretch(cloth, (ak_vec3_cspan){x, n});
    ak_cloth_energy e;
    ak_cloth_energy_compute(cloth, (ak_vec3_cspan){x, n}, (ak_vec3_cspan){vel, n}, sc.gravity, &e);
    if (json && (rc = write_json(json, time, x, n, stretch, e.total))) goto done;
    if (out && cli_has_ext(out, ".obj") && (rc = write_obj(out, cloth, x, nrm))) goto done;
    if (bake.cap && (rc = sim_bake_mesh_write(&bake, preset ? preset : "cloth", sc.dt, ak_cloth_indices(cloth),
                                              ak_vec4_make(0.72f, 0.16f, 0.18f, 1))))
        goto done;
    printf("cloth %s: %s, %zu particles, %ld steps of %.4g s (%u substeps): t = %.3g s, max stretch %.4f, energy %.6g J"
           " (kinetic %.3g)\n",
           name, solver_long[sc.desc.solver < AK_CLOTH_SOLVER_COUNT ? sc.desc.solver : 0], n,
           sc.steps, (double)sc.dt, sc.substeps, (double)time, (double)stretch, e.total, e.kinetic);
    if (gif) fprintf(stderr, "wrote %s: %d frames\n", out, frames);
    else if (bake.cap) fprintf(stderr, "wrote %s: %zu frames, %.4g s apart\n", out, bake.frames, (double)sc.dt * (double)bake.every);
    else if (out) fprintf(stderr, "wrote %s\n", out);
    if (sc.steps > 0)
        fprintf(stderr, "%.3f ms per step%s\n", 1e3 * elapsed / (double)sc.steps,
                gif ? " (including rendering)" : bake.cap ? " (including recording)" : "");

done:
    sim_bake_free(&bake);
    ak_gif_writer_discard(gw); /* a failed run leaves no partial GIF */
    free(img.pixels);
    cli_frame_free(&frame);
    cloth_run_free(&run);
    ak_cloth_scene_free(&sc);
    return rc;
}
