/* animkit particles: run a particle scene (file or preset), write JSON and/or render it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"
#include "particles_run.h"
#include "outfile.h"
#include "sim_bake.h"

static const char* const usage =
    "usage: animkit particles [SCENE.json | --preset fountain|rain|fireworks|character|fire|smoke]\n"
    "                         [--steps N]"
    " [--dt DT] [--integrator euler|symplectic|verlet|rk4] [--seed K]\n"
    "                         [--threads T] [--json OUT.json] [-o OUT.gif|OUT.png|OUT.glb|OUT.gltf]\n"
    "                         [--size WxH]\n"
    "Simulate a particle system (docs/particles.md describes the scene format).\n"
    "  --preset     a built-in scene instead of a file (character: rain and sparks on the walking\n"
    "               builtin:humanoid, which the particles collide with; fire and smoke: textured\n"
    "               sprites with colour and size over life)\n"
    "  --steps      steps to run, 0 to 100000000 (default 200)\n"
    "  --dt         step in seconds (overrides the file; default 0.01)\n"
    "  --integrator overrides the file (default symplectic)\n"
    "  --seed       seed of the emitters' random numbers (default 1)\n"
    "  --threads    threads for the step (default 1; results are identical for any count)\n"
    "  --json       write {\"time\", \"steps\", \"particles\": [{\"p\", \"v\"}]} after the last "
    "step,\n"
    "               the file's particles first, emitted ones after them\n"
    "  -o           render: a GIF of the run (up to 100 frames) or a PNG of the last step; or\n"
    "               the run as glTF (.glb, or .gltf + .bin): one animated node per particle\n"
    "  --size       image size, 8x8 to 8192x8192 (default 480x360)\n"
    "Without --json or -o prints a summary line.\n";

typedef struct renderer {
    cli_frame frame;
    bool framed;
    ak_image image;
    particles_shapes sh;
    ak_vec4* colours;
    particles_sprite_renderer sprites;
    float ground;
    const char* title;
} renderer;

static int render_frame(renderer* rd, particles_run* r, const ak_image* out) {
    cli_frame* f = &rd->frame;
    ak_raster* ras = f->raster;
    ak_vec4 sky_top, sky_bottom;
    const bool dark = particles_dark_sky(r->lib.scene, &sky_top, &sky_bottom); /* a glow shows on a dark sky */
    if (dark)
        ak_raster_clear(ras, sky_top, sky_bottom);
    else
        ak_raster_clear(ras, ak_vec4_make(0.83f, 0.87f, 0.93f, 1), ak_vec4_make(0.48f, 0.51f, 0.58f, 1));
    ak_raster_mesh meshes[2];
    size_t mc = 0;
    if (rd->sh.icount)
        meshes[mc++] = (ak_raster_mesh){.positions = {rd->sh.pos, rd->sh.vcount},
                                        .normals = {rd->sh.nrm, rd->sh.vcount},
                                        .indices = {rd->sh.idx, rd->sh.icount},
                                        .material = {.color = {0.75f, 0.72f, 0.68f, 1}}};
    if (r->ch)
        meshes[mc++] = (ak_raster_mesh){.positions = {r->ch->positions, r->ch->vertex_count},
                                        .indices = {r->ch->indices, r->ch->index_count},
                                        .material = {.color = {0.80f, 0.74f, 0.68f, 1}},
                                        .shading = AK_SHADING_FLAT};
    ak_vec3 size = ak_vec3_sub(f->bmax, f->bmin);
    float extent = ak_maxf(ak_maxf(1.3f * ak_maxf(size.x, size.z), 0.9f * size.y), 1e-3f);
    ak_raster_ground g = {.height = rd->ground,
                          .center = ak_vec3_scale(ak_vec3_add(f->bmin, f->bmax), 0.5f),
                          .half_extent = extent,
                          .grid_spacing = powf(10.0f, floorf(log10f(extent / 4.0f))),
                          .casters = meshes,
                          .caster_count = mc};
    if (dark)
        g.color = ak_vec4_make(0.26f, 0.25f, 0.25f, 1), g.line_color = ak_vec4_make(0.33f, 0.32f, 0.32f, 1);
    ak_result res = ak_raster_draw_ground(ras, &f->camera, &g);
    for (size_t m = 0; res == AK_OK && m < mc; ++m)
        res = ak_raster_draw_mesh(ras, &f->camera, &meshes[m]);
    ak_particles_state st = ak_particles_get_state(r->ps);
    if (res == AK_OK && rd->sprites.ready)
        res = particles_draw_sprites(ras, &f->camera, r->lib.scene, &rd->sprites, r->ps);
    else if (res == AK_OK)
        res = particles_draw_points(ras, &f->camera, f->width, f->height,
                                    ak_vec3_scale(ak_vec3_add(f->bmin, f->bmax), 0.5f), r->ps,
                                    rd->colours);
    char title[160];
    snprintf(title, sizeof title, "%s  t=%.2fs  %zu particle%s", rd->title, ak_particles_time(r->ps),
             st.count, cli_plural(st.count));
    if (res == AK_OK)
        res = ak_raster_draw_text(ras, 10, 10, title, f->height >= 300 ? 2 : 1,
                                  dark ? ak_vec4_make(0.9f, 0.9f, 0.92f, 1) : ak_vec4_make(0.08f, 0.09f, 0.12f, 1));
    if (res == AK_OK) res = ak_raster_resolve(ras, out);
    return res == AK_OK ? CLI_OK : cli_fail("particles", "render: %s", ak_result_string(res));
}

/* ---- output --------------------------------------------------------------------------- */

static int write_json(const char* path, particles_run* r, int steps) {
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "particles", path)) return CLI_BAD_INPUT;
    FILE* f = out.f;
    ak_particles_state st = ak_particles_get_state(r->ps);
    fprintf(f, "{\"time\": %.9g, \"steps\": %d, \"particles\": [", ak_particles_time(r->ps), steps);
    for (size_t i = 0; i < st.count; ++i) {
        ak_vec3 p = st.position[i], v = st.velocity[i];
        fprintf(f, "%s\n  {\"p\": [%.9g, %.9g, %.9g], \"v\": [%.9g, %.9g, %.9g]}", i ? "," : "",
                (double)p.x, (double)p.y, (double)p.z, (double)v.x, (double)v.y, (double)v.z);
    }
    fprintf(f, "%s]}\n", st.count ? "\n" : "");
    return cli_outfile_commit(&out, "particles");
}

int cmd_particles(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--preset", NULL, true},     {"--steps", NULL, true},  {"--dt", NULL, true},
        {"--integrator", NULL, true}, {"--seed", NULL, true},   {"--threads", NULL, true},
        {"--json", NULL, true},       {"--output", "-o", true}, {"--size", NULL, true},
    };
    cli_args a;
    int rc = cli_parse("particles", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    const char* preset = CLI_GET(&a, "--preset");
    if ((a.pos_count == 1) == (preset != NULL))
        return cli_usage("particles", "give either SCENE.json or --preset NAME");
    if (a.pos_count > 1) return cli_usage("particles", "expected one SCENE.json");
    if (preset && !particles_preset_known(preset))
        return cli_usage("particles", "--preset must be one of " AK_PARTICLES_SCENE_PRESETS ", not '%s'", preset);
    long steps = 200, seed = 1, threads = 1;
    if (CLI_GET(&a, "--steps") && !cli_parse_int(CLI_GET(&a, "--steps"), 0, 100000000, &steps))
        return cli_usage("particles", "--steps '%s' is not a whole number in 0..100000000",
                         CLI_GET(&a, "--steps"));
    if (CLI_GET(&a, "--seed") && !cli_parse_int(CLI_GET(&a, "--seed"), 0, 2147483647L, &seed))
        return cli_usage("particles", "--seed '%s' is not a whole number >= 0",
                         CLI_GET(&a, "--seed"));
    if (CLI_GET(&a, "--threads") && !cli_parse_int(CLI_GET(&a, "--threads"), 1, 64, &threads))
        return cli_usage("particles", "--threads '%s' is not a whole number in 1..64",
                         CLI_GET(&a, "--threads"));
    float dt = 0.0f;
    if (CLI_GET(&a, "--dt") &&
        (!cli_parse_float(CLI_GET(&a, "--dt"), &dt) || !(dt >= 1e-7f) || dt > 10.0f))
        return cli_usage("particles", "--dt '%s' is not a number in [1e-07, 10] (seconds)", CLI_GET(&a, "--dt"));
    ak_particles_integrator integ = AK_INTEGRATOR_DEFAULT;
    const char* in = CLI_GET(&a, "--integrator");
    if (in) {
        if (!strcmp(in, "euler"))
            integ = AK_INTEGRATOR_EULER;
        else if (!strcmp(in, "symplectic"))
            integ = AK_INTEGRATOR_SYMPLECTIC;
        else if (!strcmp(in, "verlet"))
            integ = AK_INTEGRATOR_VERLET;
        else if (!strcmp(in, "rk4"))
            integ = AK_INTEGRATOR_RK4;
        else
            return cli_usage("particles",
                             "--integrator must be euler, symplectic, verlet or rk4, not '%s'", in);
    }
    const char* out = CLI_GET(&a, "--output");
    bool gif = out && cli_has_ext(out, ".gif");
    const bool glb = sim_bake_wanted(out);
    if (out && !gif && !glb && !cli_has_ext(out, ".png"))
        return cli_usage("particles", "output '%s' must end in .gif, .png, .glb or .gltf", out);
    int width = 480, height = 360;
    if (CLI_GET(&a, "--size") && !cli_parse_size(CLI_GET(&a, "--size"), &width, &height))
        return cli_usage("particles", "--size '%s' is not WxH with 8..8192 pixels each", CLI_GET(&a, "--size"));
    const char* json = CLI_GET(&a, "--json");

    ak_particles_scene scene;
    ak_diag diag;
    if (preset) {
        if (ak_particles_scene_preset(preset, &scene, &diag) != AK_OK) return cli_fail("particles", "%s", diag.message);
    } else if (ak_particles_scene_load_file(a.pos[0], &scene, &diag) != AK_OK) {
        return cli_fail("particles", "%s", diag.message);
    }
    if (dt > 0.0f) scene.dt = dt;
    if (integ != AK_INTEGRATOR_DEFAULT) scene.integrator = integ;

    particles_character ch;
    bool use_char = preset && strcmp(preset, "character") == 0;
    memset(&ch, 0, sizeof ch);
    particles_run r;
    memset(&r, 0, sizeof r);
    renderer rd;
    memset(&rd, 0, sizeof rd);
    ak_gif_writer* gw = NULL;
    int gif_frames = 0; /* frames added to gw */
    sim_bake bake;
    memset(&bake, 0, sizeof bake);
    if ((rc = cli_work_check("particles", (double)scene.capacity * (double)steps,
                             "particle updates (capacity x steps)", "--steps or the scene's \"capacity\"")))
        goto done;
    if (use_char && particles_character_init(&ch, &rc)) goto done;
    if (glb && (rc = sim_bake_points_init(&bake, "particles", out, steps))) goto done;
    const int frames = gif ? (int)(steps < 100 ? steps : 100) : 1;
    const long every = gif && frames > 0 ? (steps + frames - 1) / frames : (steps > 0 ? steps : 1);
    if (out && !glb) {
        /* A dry run finds the bounds for a camera fixed over the whole animation. */
        if ((rc = particles_run_init(&r, &scene, use_char ? &ch : NULL, (uint64_t)seed, (uint32_t)threads)))
            goto done;
        ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
        for (size_t k = 0; k < scene.world.spheres.count; ++k) {
            const ak_particle_sphere* s = &scene.world.spheres.ptr[k];
            particles_bounds_add(&lo, &hi, ak_vec3_sub(s->center, ak_vec3_splat(s->radius)));
            particles_bounds_add(&lo, &hi, ak_vec3_add(s->center, ak_vec3_splat(s->radius)));
        }
        for (size_t k = 0; k < scene.world.boxes.count; ++k) {
            particles_bounds_add(&lo, &hi, scene.world.boxes.ptr[k].min);
            particles_bounds_add(&lo, &hi, scene.world.boxes.ptr[k].max);
        }
        for (size_t k = 0; k < scene.emitter_count; ++k)
            particles_bounds_add(&lo, &hi, scene.emitters[k].center);
        for (long s = 0; s <= steps; ++s) {
            if (s > 0 && (rc = particles_run_step(&r, (int)s - 1))) goto done;
            if (s % every && s != steps) continue;
            ak_particles_state st = ak_particles_get_state(r.ps);
            for (size_t i = 0; i < st.count; i += 1 + st.count / 4000)
                particles_bounds_add(&lo, &hi, st.position[i]);
            if (use_char)
                for (size_t v = 0; v < ch.vertex_count; v += 7)
                    particles_bounds_add(&lo, &hi, ch.positions[v]);
        }
        particles_run_free(&r);
        memset(&r, 0, sizeof r);
        if (!(lo.x <= hi.x)) lo = ak_vec3_splat(-1), hi = ak_vec3_splat(1);
        /* at least 1 m on every axis: a single particle (or a flat sheet) framed at its own
         * zero size put the camera on top of it, showing nothing but the ground */
        const ak_vec3 mid = ak_vec3_scale(ak_vec3_add(lo, hi), 0.5f);
        lo = ak_vec3_min(lo, ak_vec3_sub(mid, ak_vec3_splat(0.5f)));
        hi = ak_vec3_max(hi, ak_vec3_add(mid, ak_vec3_splat(0.5f)));
        rd.ground = lo.y;
        for (size_t k = 0; k < scene.world.planes.count; ++k) {
            ak_vec3 n = ak_vec3_normalize(scene.world.planes.ptr[k].normal);
            if (n.y > 0.99f)
                rd.ground = scene.world.planes.ptr[k].d / n.y, lo.y = fminf(lo.y, rd.ground);
        }
        if (use_char && particles_character_pose(&ch, 0.0f, 0.0f) != AK_OK) {
            rc = cli_fail("particles", "cannot pose the character");
            goto done;
        }
        if (cli_frame_init(&rd.frame, NULL, width, height, lo, hi, 0.5f) ||
            cli_image_alloc(&rd.image, width, height)) {
            rc = cli_fail("particles", "out of memory for a %dx%d image", width, height);
            goto done;
        }
        rd.framed = true;
        rd.colours = calloc(scene.capacity + 1, sizeof(ak_vec4));
        if (!rd.colours || !particles_shapes_build(&rd.sh, &scene)) {
            rc = cli_fail("particles", "out of memory");
            goto done;
        }
        if ((rc = particles_sprites_init(&rd.sprites, &scene, "particles"))) goto done;
        rd.title = preset ? preset : "particles";
        if (gif) {
            ak_gif_desc gd = {.width = width,
                              .height = height,
                              .delay_cs =
                                  (int)fmaxf(2.0f, roundf(100.0f * scene.dt * (float)every))};
            ak_result res = ak_gif_writer_create(out, &gd, NULL, &gw);
            if (res != AK_OK) {
                rc = cli_fail("particles", "%s: %s", out, ak_result_string(res));
                goto done;
            }
        }
    }
    if ((rc = particles_run_init(&r, &scene, use_char ? &ch : NULL, (uint64_t)seed, (uint32_t)threads)))
        goto done;
    const double t0 = cli_now();
    for (long s = 0; s <= steps; ++s) {
        if (s > 0 && (rc = particles_run_step(&r, (int)s - 1))) goto done;
        cli_progress("particles", (size_t)s, (size_t)steps);
        if (glb) {
            ak_particles_state st = ak_particles_get_state(r.ps);
            if ((rc = sim_bake_points_add(&bake, s, st.position, st.id, st.count))) goto done;
        }
        if (gw && (s % every == 0 || s == steps)) {
            if ((rc = render_frame(&rd, &r, &rd.image))) goto done;
            ak_result res = ak_gif_writer_add_frame(gw, &rd.image);
            gif_frames += res == AK_OK;
            if (res != AK_OK) {
                rc = cli_fail("particles", "%s: %s", out, ak_result_string(res));
                goto done;
            }
        }
    }
    const double elapsed = cli_now() - t0;
    if (json && (rc = write_json(json, &r, (int)steps))) goto done;
    if (json) cli_wrote(json, "%zu particles after %ld steps", ak_particles_count(r.ps), steps);
    if (!json && !out) {
        const size_t alive = ak_particles_count(r.ps);
        printf("particles %s: %ld step%s of %.4g s (t = %.3g s) in %.3f s (%.3f ms/step), %zu particle%s alive"
               " (capacity %zu)\n",
               preset ? preset : a.pos[0], steps, cli_plural((size_t)steps), (double)scene.dt,
               (double)ak_particles_time(r.ps), elapsed, steps ? 1e3 * elapsed / (double)steps : 0.0, alive,
               cli_plural(alive), ak_particles_capacity(r.ps));
    }
    if (glb) {
        if ((rc = sim_bake_points_write(&bake, preset ? preset : "particles", scene.dt))) goto done;
        cli_wrote(out, "%zu frames, %.4g s apart", bake.frames, (double)scene.dt * (double)bake.every);
    } else if (out && !gif) {
        if ((rc = render_frame(&rd, &r, &rd.image))) goto done;
        ak_result res = ak_png_write(out, &rd.image);
        if (res != AK_OK) rc = cli_fail("particles", "%s: %s", out, ak_result_string(res));
        else cli_wrote(out, "the last step");
    }
done:
    if (gw && rc != CLI_OK) ak_gif_writer_discard(gw); /* a failed run leaves no partial GIF */
    else if (gw) {
        ak_result res = ak_gif_writer_finish(gw);
        if (res != AK_OK) rc = cli_fail("particles", "%s: %s", out, ak_result_string(res));
        else cli_wrote(out, "%d frames", gif_frames);
    }
    sim_bake_free(&bake);
    particles_run_free(&r);
    if (rd.framed) cli_frame_free(&rd.frame);
    free(rd.image.pixels);
    free(rd.colours);
    particles_sprites_free(&rd.sprites);
    particles_shapes_free(&rd.sh);
    if (use_char) particles_character_free(&ch);
    ak_particles_scene_free(&scene);
    return rc;
}
