/* animkit rigid: simulate a rigid-body scene or preset; write JSON, PNG, GIF or glTF. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "outfile.h"
#include "render.h"
#include "sim_bake.h"

static const char* const usage =
    "usage: animkit rigid [SCENE.json | --preset "
    "stack|pyramid|dominoes|avalanche|ragdoll|incline]\n"
    "                     [--steps N] [--dt DT] [--substeps S] [--threads T] [--json OUT.json]\n"
    "                     [-o OUT.gif|OUT.png|OUT.glb]\n"
    "Simulate rigid bodies (spheres, boxes, capsules, hulls, compounds, static planes, meshes and\n"
    "heightfields) and joints with XPBD "
    "substeps,\n"
    "contacts, Coulomb friction and restitution: a 10-box stack, a 20-layer pyramid, dominoes, an\n"
    "avalanche down a slope, builtin:humanoid as a ragdoll, boxes on an incline; or the scene a\n"
    "JSON file describes (docs/rigid.md lists every key). --json writes {\"time\", \"bodies\": "
    "[{\"position\", \"orientation\", \"velocity\",\n"
    "\"angular_velocity\"}], \"max_penetration\", \"energy\"} of the final state (world space);\n"
    "-o renders the run (GIF), its last frame (PNG), or bakes it as glTF node animation\n"
    "(.glb: one node per body, translation and rotation channels).\n"
    "Exit status: 0 success, 1 bad scene or a blow-up (named by its step), 2 bad usage.\n";

/* ---- the bodies as one mesh (the library's: every shape drawn as itself) ------------------ */

typedef struct body_mesh {
    ak_vec3 *pos, *nrm;
    uint32_t* idx;
    size_t vcount, icount;
} body_mesh;

static void mesh_free(body_mesh* m) {
    free(m->pos), free(m->nrm), free(m->idx);
    memset(m, 0, sizeof *m);
}

/* Most vertices drawn (1.6 GB of positions and normals): a scene's meshes are bounded by its
 * file's size, far below this; the check keeps the 32-bit indices exact. */
#define DRAW_MAX_VERTICES ((size_t)1 << 26)

static bool mesh_build(body_mesh* m, const ak_rigid_model* model) {
    memset(m, 0, sizeof *m);
    ak_rigid_world_mesh_size(model, &m->vcount, &m->icount);
    if (m->vcount > DRAW_MAX_VERTICES) return false;
    m->pos = malloc((m->vcount + 1) * sizeof(ak_vec3));
    m->nrm = malloc((m->vcount + 1) * sizeof(ak_vec3));
    m->idx = malloc((m->icount + 1) * sizeof(uint32_t));
    return m->pos && m->nrm && m->idx;
}

static ak_result mesh_pose(body_mesh* m, const ak_rigid_model* model, const ak_vec3* x,
                           const ak_quat* q) {
    const size_t n = ak_rigid_body_count(model);
    return ak_rigid_world_mesh(
        model, (ak_vec3_cspan){x, n}, (ak_quat_cspan){q, n}, (ak_vec3_span){m->pos, m->vcount + 1},
        (ak_vec3_span){m->nrm, m->vcount + 1}, (ak_u32_span){m->idx, m->icount + 1});
}

/* ---- output ------------------------------------------------------------------------------ */

static void put_vec(FILE* f, const char* key, const float* c, int count) {
    fprintf(f, "\"%s\": [", key);
    for (int k = 0; k < count; ++k) fprintf(f, "%s%.9g", k ? ", " : "", (double)c[k]);
    fprintf(f, "]");
}

static int write_json(const char* path, float time, size_t n, const ak_vec3* x, const ak_quat* q,
                      const ak_vec3* v, const ak_vec3* w, float pen, double energy) {
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "rigid", path)) return CLI_BAD_INPUT;
    FILE* f = out.f;
    fprintf(f, "{\"time\": %.9g, \"bodies\": [", (double)time);
    for (size_t i = 0; i < n; ++i) {
        const float p[3] = {x[i].x, x[i].y, x[i].z}, o[4] = {q[i].x, q[i].y, q[i].z, q[i].w};
        const float vv[3] = {v[i].x, v[i].y, v[i].z}, ww[3] = {w[i].x, w[i].y, w[i].z};
        fprintf(f, "%s{", i ? ", " : "");
        put_vec(f, "position", p, 3);
        fprintf(f, ", ");
        put_vec(f, "orientation", o, 4);
        fprintf(f, ", ");
        put_vec(f, "velocity", vv, 3);
        fprintf(f, ", ");
        put_vec(f, "angular_velocity", ww, 3);
        fprintf(f, "}");
    }
    fprintf(f, "], \"max_penetration\": %.9g, \"energy\": %.9g}\n", (double)pen, energy);
    return cli_outfile_commit(&out, "rigid");
}

/* ---- the command -------------------------------------------------------------------------- */

int cmd_rigid(int argc, char** argv) {
    static const cli_opt opts[] = {{"--preset", NULL, true},  {"--steps", NULL, true},
                                   {"--dt", NULL, true},      {"--substeps", NULL, true},
                                   {"--threads", NULL, true}, {"--json", NULL, true},
                                   {"--output", "-o", true}};
    cli_args a;
    int rc = cli_parse("rigid", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    const char* preset = CLI_GET(&a, "--preset");
    if (a.pos_count > 1) return cli_usage("rigid", "expected at most one SCENE.json");
    if ((a.pos_count == 1) == (preset != NULL))
        return cli_usage("rigid", "give either SCENE.json or --preset NAME");
    const char* out = CLI_GET(&a, "--output");
    const char* json = CLI_GET(&a, "--json");
    if (out && !cli_has_ext(out, ".gif") && !cli_has_ext(out, ".png") && !cli_has_ext(out, ".glb"))
        return cli_usage("rigid", "output '%s' must end in .gif, .png or .glb", out);
    ak_rigid_scene sc;
    ak_diag diag;
    const char* name = preset ? preset : a.pos[0];
    ak_rigid_scene_defaults(&sc);
    if (preset) {
        const ak_result res = ak_rigid_scene_preset(preset, &sc, &diag);
        if (res == AK_ERR_NOT_FOUND)
            return cli_usage("rigid", "unknown preset '%s' (" AK_RIGID_SCENE_PRESETS ")", preset);
        if (res != AK_OK) return cli_fail("rigid", "%s", diag.message);
    } else if (ak_rigid_scene_load_file(a.pos[0], &sc, &diag) != AK_OK) {
        ak_rigid_scene_free(&sc);
        return cli_fail("rigid", "%s", diag.message);
    }
    const char* v;
    long lv;
    if ((v = CLI_GET(&a, "--steps"))) {
        if (!cli_parse_int(v, 0, AK_RIGID_SCENE_MAX_STEPS, &lv))
            rc = cli_usage_int("rigid", "--steps", v, 0, AK_RIGID_SCENE_MAX_STEPS);
        else
            sc.steps = lv;
    }
    if (!rc && (v = CLI_GET(&a, "--dt"))) {
        float dt;
        if (!cli_parse_float(v, &dt) || !(dt >= 1e-6f) || dt > 1.0f)
            rc = cli_usage("rigid", "--dt must be in [1e-06, 1] seconds");
        else
            sc.dt = dt;
    }
    if (!rc && (v = CLI_GET(&a, "--substeps"))) {
        if (!cli_parse_int(v, 1, AK_RIGID_SCENE_MAX_SUBSTEPS, &lv))
            rc = cli_usage_int("rigid", "--substeps", v, 1, AK_RIGID_SCENE_MAX_SUBSTEPS);
        else
            sc.substeps = (uint32_t)lv;
    }
    if (!rc && (v = CLI_GET(&a, "--threads"))) {
        if (!cli_parse_int(v, 1, AK_RIGID_MAX_THREADS, &lv))
            rc = cli_usage_int("rigid", "--threads", v, 1, AK_RIGID_MAX_THREADS);
        else
            sc.thread_count = (uint32_t)lv;
    }
    const size_t n = sc.body_count;
    if (!rc)
        rc = cli_work_check("rigid", (double)n * (double)sc.steps * (double)sc.substeps * 4.0,
                            "body updates (bodies x steps x substeps x 4)",
                            "--steps, --substeps or the body count");
    if (rc) {
        ak_rigid_scene_free(&sc);
        return rc;
    }

    ak_rigid_scene_run run;
    memset(&run, 0, sizeof run);
    body_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    cli_frame frame;
    memset(&frame, 0, sizeof frame);
    ak_image img = {0};
    ak_gif_writer* gw = NULL;
    /* -o OUT.glb: the states of every `every`-th step, baked as node animation */
    ak_vec3* rec_x = NULL;
    ak_quat* rec_q = NULL;
    size_t rec_frames = 0, rec_cap = 0;
    long every = 1;
    ak_scene* baked = NULL;
    ak_result r;

    if (ak_rigid_scene_run_init(&run, &sc, name, &diag) != AK_OK) {
        rc = cli_fail("rigid", "%s", diag.message);
        goto done;
    }
    const ak_rigid_model* model = run.model;
    const ak_vec3* x = run.positions;
    const ak_quat* q = run.orientations;
    const bool gif = out && cli_has_ext(out, ".gif"), png = out && cli_has_ext(out, ".png");
    if (gif || png) {
        if (!mesh_build(&mesh, model)) {
            rc = cli_fail("rigid",
                          "%s: the bodies' mesh (%zu vertices) is too large to draw or "
                          "out of memory",
                          name, mesh.vcount);
            goto done;
        }
        if ((r = mesh_pose(&mesh, model, x, q)) != AK_OK) {
            rc = cli_fail("rigid", "%s: cannot mesh the bodies: %s", name, ak_result_string(r));
            goto done;
        }
    }
    if (out && sim_bake_wanted(out)) {
        /* every step a frame, unless that passes the bake's frame limit or SIM_BAKE_BUDGET */
        size_t by_mem = SIM_BAKE_BUDGET / ((n ? n : 1) * (sizeof(ak_vec3) + sizeof(ak_quat)));
        size_t max_frames = by_mem < AK_SCENE_BAKE_MAX_FRAMES ? by_mem : AK_SCENE_BAKE_MAX_FRAMES;
        if (max_frames < 2) {
            rc = cli_fail("rigid", "%s: %zu bodies are too many to bake", out, n);
            goto done;
        }
        if (sc.steps > 0 && (size_t)sc.steps + 1 > max_frames)
            every = (long)(((size_t)sc.steps + max_frames - 2) / (max_frames - 1));
        rec_cap = (size_t)(sc.steps / every) + 1;
        rec_x = malloc(rec_cap * (n ? n : 1) * sizeof *rec_x);
        rec_q = malloc(rec_cap * (n ? n : 1) * sizeof *rec_q);
        if (!rec_x || !rec_q) {
            rc = cli_fail("rigid", "%s: out of memory for %zu frames", out, rec_cap);
            goto done;
        }
    }
    if (gif || png) {
        ak_vec3 lo = ak_vec3_splat(-1.0f), hi = ak_vec3_splat(1.0f);
        for (size_t v2 = 0; v2 < mesh.vcount; ++v2)
            lo = ak_vec3_min(lo, mesh.pos[v2]), hi = ak_vec3_max(hi, mesh.pos[v2]);
        if (cli_frame_init(&frame, NULL, 480, 360, lo, hi, 0.6f) ||
            cli_image_alloc(&img, 480, 360)) {
            rc = cli_fail("rigid", "out of memory");
            goto done;
        }
        if (gif &&
            ak_gif_writer_create(out, &(ak_gif_desc){.width = 480, .height = 360, .delay_cs = 4},
                                 NULL, &gw) != AK_OK) {
            rc = cli_fail("rigid", "%s: cannot create the file", out);
            goto done;
        }
    }

    const double t0 = cli_now();
    int frames = 0;
    float time = 0.0f;
    for (long step = 0; step <= sc.steps; ++step) {
        if ((gif && (step == 0 || floorf(time * 25.0f) != floorf((time - sc.dt) * 25.0f))) ||
            (png && step == sc.steps)) {
            if ((r = mesh_pose(&mesh, model, x, q)) != AK_OK) {
                rc = cli_fail("rigid", "%s: cannot mesh the bodies at step %ld: %s", name, step,
                              ak_result_string(r));
                goto done;
            }
            ak_raster_mesh extra = {
                .positions = {mesh.pos, mesh.vcount},
                .normals = {mesh.nrm, mesh.vcount},
                .indices = {mesh.idx, mesh.icount},
                .material = {.color = {0.80f, 0.55f, 0.25f, 1}, .specular = 0.2f}};
            char title[160];
            snprintf(title, sizeof title, "rigid %s  t=%.2fs", preset ? preset : "", (double)time);
            cli_draw_opts o = {.title = title, .extra = &extra, .extra_count = 1};
            r = cli_frame_draw(&frame, NULL, &o, &img);
            if (r == AK_OK) r = gif ? ak_gif_writer_add_frame(gw, &img) : ak_png_write(out, &img);
            if (r != AK_OK) {
                rc = cli_fail("rigid", "%s: cannot render or write: %s", out, ak_result_string(r));
                goto done;
            }
            ++frames;
        }
        if (rec_cap && step % every == 0 && rec_frames < rec_cap) {
            memcpy(rec_x + rec_frames * n, x, n * sizeof *rec_x);
            memcpy(rec_q + rec_frames * n, q, n * sizeof *rec_q);
            ++rec_frames;
        }
        if (step == sc.steps) break;
        r = ak_rigid_scene_run_step(&run);
        if (r == AK_ERR_BAD_DATA) {
            rc = cli_fail("rigid",
                          "%s: the simulation blew up at step %ld (t = %.4g s): a non-finite "
                          "state; lower --dt or"
                          " raise --substeps",
                          name, step + 1, (double)time);
            goto done;
        }
        if (r != AK_OK) {
            rc = cli_fail("rigid", "%s: step %ld failed: %s", name, step + 1, ak_result_string(r));
            goto done;
        }
        time = (float)run.time;
        cli_progress("rigid", (size_t)step + 1, (size_t)sc.steps);
    }
    const double elapsed = cli_now() - t0;
    if (gw) {
        r = ak_gif_writer_finish(gw);
        gw = NULL;
        if (r != AK_OK) {
            rc = cli_fail("rigid", "%s: cannot write: %s", out, ak_result_string(r));
            goto done;
        }
    }
    const double energy = ak_rigid_scene_run_energy(&run);
    const float pen = run.max_penetration;
    if (json &&
        (rc = write_json(json, time, n, x, q, run.velocities, run.angular_velocities, pen, energy)))
        goto done;
    if (rec_cap) {
        ak_rigid_bake_desc bd = {.name = preset ? preset : "rigid",
                                 .model = model,
                                 .frame_count = rec_frames,
                                 .positions = rec_x,
                                 .orientations = rec_q,
                                 .frame_time = sc.dt * (float)every};
        if (sc.ragdoll_bone_count) {
            /* the ragdoll preset: its character, the run as its skeleton's animation */
            r = ak_builtin_create(sc.ragdoll_character,
                                  &(ak_builtin_desc){.cell_size = sc.ragdoll_cell_size}, NULL,
                                  &baked);
            ak_clip* clip = NULL;
            if (r == AK_OK && (!baked->clip_count ||
                               ak_skeleton_joint_count(baked->skeleton) != sc.ragdoll_bone_count)) {
                snprintf(diag.message, sizeof diag.message,
                         "builtin:%s is not the ragdoll's character", sc.ragdoll_character);
                r = AK_ERR_BAD_DATA;
            }
            if (r == AK_OK) {
                ak_rigid_bake_ragdoll_desc rb = {
                    .name = "ragdoll",
                    .skeleton = baked->skeleton,
                    .bones = {sc.ragdoll_bones, sc.ragdoll_bone_count},
                    .fallback_pose = {sc.ragdoll_pose, sc.ragdoll_bone_count},
                    .body_count = n,
                    .frame_count = rec_frames,
                    .positions = rec_x,
                    .orientations = rec_q,
                    .frame_time = sc.dt * (float)every};
                r = ak_rigid_bake_ragdoll_clip(&rb, &baked->alloc, &clip, &diag);
            }
            if (r == AK_OK) { /* the baked run replaces the character's own clips */
                for (size_t c = 0; c < baked->clip_count; ++c) ak_clip_destroy(baked->clips[c]);
                baked->clips[0] = clip;
                baked->clip_count = 1;
            }
        } else {
            r = ak_rigid_bake_scene(&bd, NULL, &baked, &diag);
        }
        if (r == AK_OK) r = ak_io_save(out, baked, NULL, &diag);
        if (r == AK_ERR_UNSUPPORTED) {
            rc = cli_fail("rigid", "%s: %s; use fewer --steps", out, diag.message);
            goto done;
        }
        if (r != AK_OK) {
            rc = cli_fail("rigid", "%s: %s (%s)", out, diag.message, ak_result_string(r));
            goto done;
        }
    }
    printf("rigid %s: %zu bodies, %zu joints, %ld steps of %.4g s (%u substeps): t = %.3g s, max "
           "penetration %.3g m, energy %.6g J\n",
           name, n, sc.joint_count, sc.steps, (double)sc.dt, sc.substeps, (double)time, (double)pen,
           energy);
    if (run.dropped_contacts)
        fprintf(stderr,
                "animkit rigid: warning: %s: %llu contact points dropped over max_contacts (from "
                "step %ld on): bodies may sink into each other; raise \"max_contacts\" in the "
                "scene (0: 16 per body + 64)\n",
                name, (unsigned long long)run.dropped_contacts, run.dropped_first_step);
    if (gif)
        cli_wrote(out, "%d frames", frames);
    else if (rec_cap && sc.ragdoll_bone_count)
        cli_wrote(out, "%zu frames, %.4g s apart, builtin:%s's skeleton animated", rec_frames,
                  (double)sc.dt * (double)every, sc.ragdoll_character);
    else if (rec_cap)
        cli_wrote(out, "%zu frames, %.4g s apart, one node per body", rec_frames,
                  (double)sc.dt * (double)every);
    else if (out)
        cli_wrote(out, NULL);
    if (sc.steps > 0 && !cli_quiet)
        fprintf(stderr, "%.3f ms per step\n", 1e3 * elapsed / (double)sc.steps);

done:
    free(rec_x);
    free(rec_q);
    ak_scene_destroy(baked);
    ak_gif_writer_discard(gw);
    free(img.pixels);
    cli_frame_free(&frame);
    mesh_free(&mesh);
    ak_rigid_scene_run_free(&run);
    ak_rigid_scene_free(&sc);
    return rc;
}
