/* animkit particles: run a particle scene (file or preset), write JSON and/or render it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_json.h"
#include "render.h"
#include "scene_particles.h"

static const char* const usage =
    "usage: animkit particles [SCENE.json | --preset fountain|rain|fireworks|character] [--steps "
    "N]\n"
    "                         [--dt DT] [--integrator euler|symplectic|verlet|rk4] [--seed K]\n"
    "                         [--threads T] [--json OUT.json] [-o OUT.gif|OUT.png] [--size WxH]\n"
    "Simulate a particle system (docs/particles.md describes the scene format).\n"
    "  --preset     a built-in scene instead of a file (character: rain and sparks on the walking\n"
    "               builtin:humanoid, which the particles collide with)\n"
    "  --steps      steps to run (default 200)\n"
    "  --dt         step in seconds (overrides the file; default 0.01)\n"
    "  --integrator overrides the file (default symplectic)\n"
    "  --seed       seed of the emitters' random numbers (default 1)\n"
    "  --threads    threads for the step (default 1; results are identical for any count)\n"
    "  --json       write {\"time\", \"steps\", \"particles\": [{\"p\", \"v\"}]} after the last "
    "step,\n"
    "               the file's particles first, emitted ones after them\n"
    "  -o           render: a GIF of the run (up to 100 frames) or a PNG of the last step\n"
    "  --size       image size (default 480x360)\n";

/* ---- presets -------------------------------------------------------------------------- */

static ak_particle_emitter emitter_base(void) {
    ak_particle_emitter e = {.direction = {0, 1, 0},
                             .cone_angle = 0.3f,
                             .speed_min = 1,
                             .speed_max = 2,
                             .lifetime_min = 1,
                             .lifetime_max = 2,
                             .size_min = 0.03f,
                             .size_max = 0.03f,
                             .mass = 1};
    return e;
}

/* Fills s for a preset; false when out of memory. */
static bool preset_scene(const char* name, particles_scene* s) {
    memset(s, 0, sizeof *s);
    s->dt = 0.01f;
    s->integrator = AK_INTEGRATOR_SYMPLECTIC;
    s->capacity = 60000;
    s->world.gravity = ak_vec3_make(0, -9.81f, 0);
    s->planes = calloc(1, sizeof *s->planes);
    s->spheres = calloc(1, sizeof *s->spheres);
    s->emitters = calloc(4, sizeof *s->emitters);
    s->bursts = calloc(4, sizeof *s->bursts);
    if (!s->planes || !s->spheres || !s->emitters || !s->bursts) return false;
    s->planes[0] = (ak_particle_plane){.normal = {0, 1, 0}, .restitution = 0.4f, .friction = 0.3f};
    s->world.planes = (ak_particle_plane_cspan){s->planes, 1};
    ak_particle_emitter e = emitter_base();
    if (strcmp(name, "fountain") == 0) {
        e.center = ak_vec3_make(0, 0.05f, 0);
        e.cone_angle = 0.18f, e.speed_min = 5.0f, e.speed_max = 5.6f;
        e.lifetime_min = 2.5f, e.lifetime_max = 3.5f;
        e.colour = ak_vec4_make(0.25f, 0.55f, 1.0f, 1), e.rate = 1500.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->spheres[0] = (ak_particle_sphere){
            .center = {0.45f, 0.35f, 0}, .radius = 0.35f, .restitution = 0.3f, .friction = 0.2f};
        s->world.spheres = (ak_particle_sphere_cspan){s->spheres, 1};
        s->world.drag_linear = 0.02f;
    } else if (strcmp(name, "rain") == 0) {
        e.shape = AK_EMITTER_BOX, e.center = ak_vec3_make(0, 4, 0),
        e.half_extents = ak_vec3_make(2, 0.1f, 2);
        e.direction = ak_vec3_make(0, -1, 0), e.cone_angle = 0.02f, e.speed_min = 3,
        e.speed_max = 4;
        e.lifetime_min = 2.5f, e.lifetime_max = 3.0f, e.size_min = 0.015f, e.size_max = 0.02f;
        e.colour = ak_vec4_make(0.55f, 0.7f, 1.0f, 1), e.rate = 3000.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->spheres[0] = (ak_particle_sphere){
            .center = {0, 1.2f, 0}, .radius = 0.8f, .restitution = 0.2f, .friction = 0.1f};
        s->world.spheres = (ak_particle_sphere_cspan){s->spheres, 1};
        s->world.wind = ak_vec3_make(1.5f, 0, 0);
        s->world.drag_linear = 0.3f;
        s->planes[0].restitution = 0.1f;
    } else if (strcmp(name, "fireworks") == 0) {
        const ak_vec4 colours[4] = {
            {1, 0.3f, 0.2f, 1}, {0.3f, 1, 0.4f, 1}, {1, 0.85f, 0.3f, 1}, {0.6f, 0.5f, 1, 1}};
        const float x[4] = {-1.2f, 0.9f, 0.0f, 1.6f}, y[4] = {3.0f, 3.6f, 4.2f, 2.8f};
        for (int k = 0; k < 4; ++k) {
            ak_particle_emitter f = emitter_base();
            f.shape = AK_EMITTER_SPHERE, f.center = ak_vec3_make(x[k], y[k], -0.5f * k),
            f.radius = 0.05f;
            f.cone_angle = AK_PI, f.speed_min = 2.5f, f.speed_max = 3.2f, f.lifetime_min = 1.2f,
            f.lifetime_max = 1.8f;
            f.colour = colours[k];
            s->emitters[k] = f;
            s->bursts[k] =
                (particles_burst){.count = 800, .start = 0.45f * (float)k, .interval = 1.8f};
        }
        s->emitter_count = 4;
        s->world.drag_quadratic = 0.02f;
        s->world.gravity = ak_vec3_make(0, -3.0f, 0);
    } else if (strcmp(name, "character") == 0) {
        /* Rain on the character (collides with its posed mesh) and sparks from its surface. */
        e.shape = AK_EMITTER_BOX, e.center = ak_vec3_make(0, 2.6f, 0),
        e.half_extents = ak_vec3_make(0.7f, 0.05f, 0.7f);
        e.direction = ak_vec3_make(0, -1, 0), e.cone_angle = 0.02f, e.speed_min = 2,
        e.speed_max = 2.5f;
        e.lifetime_min = 2, e.lifetime_max = 2.5f, e.size_min = 0.012f, e.size_max = 0.016f;
        e.colour = ak_vec4_make(0.45f, 0.65f, 1.0f, 1), e.rate = 2500.0f;
        s->emitters[0] = e;
        ak_particle_emitter sp = emitter_base();
        sp.shape = AK_EMITTER_MESH, sp.cone_angle = 0.5f, sp.speed_min = 0.3f, sp.speed_max = 0.8f;
        sp.lifetime_min = 0.6f, sp.lifetime_max = 1.0f, sp.size_min = 0.01f, sp.size_max = 0.015f;
        sp.colour = ak_vec4_make(1.0f, 0.55f, 0.15f, 1), sp.rate = 800.0f,
        sp.base_velocity = ak_vec3_make(0, 0.5f, 0);
        s->emitters[1] = sp;
        s->emitter_count = 2;
        s->planes[0].restitution = 0.2f;
    } else {
        return false;
    }
    return true;
}

/* ---- the character ----------------------------------------------------------------------- */

typedef struct character {
    ak_scene* scene;
    cli_poser poser;
    bool posed;
    ak_vec3* positions; /* all meshes concatenated */
    uint32_t* indices;
    size_t vertex_count, index_count;
    ak_particle_mesh* collider;
    float* cdf;
} character;

static void character_gather(character* c) {
    size_t v = 0;
    for (size_t m = 0; m < c->scene->mesh_count; ++m) {
        const ak_mesh* mesh = c->scene->meshes[m].mesh;
        if (!mesh) continue;
        memcpy(c->positions + v, c->poser.positions[m], mesh->vertex_count * sizeof(ak_vec3));
        v += mesh->vertex_count;
    }
}

static int character_init(character* c, int* rc) {
    memset(c, 0, sizeof *c);
    if ((*rc = cli_load_scene("particles", "builtin:humanoid", &c->scene))) return *rc;
    if (cli_poser_init(&c->poser, c->scene)) return *rc = cli_fail("particles", "out of memory");
    c->posed = true;
    for (size_t m = 0; m < c->scene->mesh_count; ++m) {
        const ak_mesh* mesh = c->scene->meshes[m].mesh;
        if (!mesh) continue;
        c->vertex_count += mesh->vertex_count;
        c->index_count += 3 * mesh->triangle_count;
    }
    c->positions = calloc(c->vertex_count + 1, sizeof(ak_vec3));
    c->indices = calloc(c->index_count + 1, sizeof(uint32_t));
    c->cdf = calloc(c->index_count / 3 + 1, sizeof(float));
    if (!c->positions || !c->indices || !c->cdf)
        return *rc = cli_fail("particles", "out of memory");
    size_t v = 0, k = 0;
    for (size_t m = 0; m < c->scene->mesh_count; ++m) {
        const ak_mesh* mesh = c->scene->meshes[m].mesh;
        if (!mesh) continue;
        for (size_t i = 0; i < 3 * mesh->triangle_count; ++i)
            c->indices[k++] = (uint32_t)(mesh->indices[i] + v);
        v += mesh->vertex_count;
    }
    if (cli_poser_pose(&c->poser, 0, 0.0f, false, CLI_LBS) != AK_OK)
        return *rc = cli_fail("particles", "cannot pose the character");
    character_gather(c);
    ak_particle_mesh_desc md = {.positions = {c->positions, c->vertex_count},
                                .indices = {c->indices, c->index_count},
                                .restitution = 0.2f,
                                .friction = 0.3f};
    if (ak_particle_mesh_create(&md, NULL, &c->collider) != AK_OK)
        return *rc = cli_fail("particles", "cannot build the character collider");
    return *rc = CLI_OK;
}

/* Pose at time t; the collider gets the pose with the elapsed time since the last one. */
static ak_result character_pose(character* c, float t, float elapsed) {
    ak_result r = cli_poser_pose(&c->poser, 0, t, false, CLI_LBS);
    if (r != AK_OK) return r;
    character_gather(c);
    return ak_particle_mesh_update(c->collider, (ak_vec3_cspan){c->positions, c->vertex_count},
                                   elapsed);
}

static void character_free(character* c) {
    if (c->posed) cli_poser_free(&c->poser);
    ak_particle_mesh_destroy(c->collider);
    free(c->positions);
    free(c->indices);
    free(c->cdf);
    ak_scene_destroy(c->scene);
}

/* ---- simulation ------------------------------------------------------------------------ */

typedef struct run {
    particles_scene* scene;
    ak_particles* ps;
    character* ch; /* NULL unless the character preset */
    const ak_particle_mesh* meshes[1];
    ak_particles_world world;
    uint32_t* fired; /* bursts fired per emitter */
} run;

static int run_init(run* r, particles_scene* s, character* ch, uint64_t seed, uint32_t threads) {
    memset(r, 0, sizeof *r);
    r->scene = s;
    r->ch = ch;
    ak_particles_desc d = {.capacity = s->capacity,
                           .integrator = s->integrator,
                           .seed = seed,
                           .thread_count = threads};
    ak_result res = ak_particles_create(&d, NULL, &r->ps);
    if (res != AK_OK)
        return cli_fail("particles", "cannot create the system: %s", ak_result_string(res));
    for (size_t i = 0; i < s->particle_count; ++i) {
        res = ak_particles_add(r->ps, &s->particles[i], NULL);
        if (res != AK_OK)
            return cli_fail("particles", "particle %zu: %s", i, ak_result_string(res));
    }
    r->fired = calloc(s->emitter_count + 1, sizeof(uint32_t));
    if (!r->fired) return cli_fail("particles", "out of memory");
    for (size_t e = 0; e < s->emitter_count; ++e) s->emitters[e].carry = 0.0;
    r->world = s->world;
    if (ch) {
        r->meshes[0] = ch->collider;
        r->world.meshes = (ak_particle_mesh_cspan){r->meshes, 1};
        for (size_t e = 0; e < s->emitter_count; ++e)
            if (s->emitters[e].shape == AK_EMITTER_MESH) {
                s->emitters[e].mesh_positions = (ak_vec3_cspan){ch->positions, ch->vertex_count};
                s->emitters[e].mesh_indices = (ak_u32_cspan){ch->indices, ch->index_count};
                s->emitters[e].mesh_area_cdf = (ak_f32_span){ch->cdf, ch->index_count / 3};
            }
    }
    return CLI_OK;
}

/* One step: pose the character for the end of the step, emit, step. */
static int run_step(run* r, int step) {
    particles_scene* s = r->scene;
    const float dt = s->dt;
    const double t1 = (double)(step + 1) * dt;
    ak_result res = AK_OK;
    if (r->ch) res = character_pose(r->ch, (float)t1, dt);
    for (size_t e = 0; e < s->emitter_count && res == AK_OK; ++e) {
        res = ak_particles_emit(r->ps, &s->emitters[e], dt, NULL);
        /* Bursts due before the end of this step (start, start + interval, ...). */
        const particles_burst* b = &s->bursts[e];
        while (res == AK_OK && b->count > 0 && (b->interval > 0.0f || r->fired[e] == 0)) {
            if ((double)b->start + (double)r->fired[e] * (double)b->interval >= t1) break;
            res = ak_particles_burst(r->ps, &s->emitters[e], b->count, NULL);
            ++r->fired[e];
        }
    }
    if (res == AK_OK) res = ak_particles_step(r->ps, &r->world, dt);
    if (res != AK_OK) return cli_fail("particles", "step %d: %s", step, ak_result_string(res));
    return CLI_OK;
}

static void run_free(run* r) {
    ak_particles_destroy(r->ps);
    free(r->fired);
}

/* ---- rendering ------------------------------------------------------------------------- */

typedef struct shapes {
    ak_vec3* pos;
    ak_vec3* nrm;
    uint32_t* idx;
    size_t vcount, icount;
} shapes;

/* UV spheres and boxes of the colliders as one triangle mesh. */
static bool shapes_build(shapes* sh, const particles_scene* s) {
    enum { SEG = 24, RINGS = 14 };
    size_t nv = s->world.spheres.count * (SEG + 1) * (RINGS + 1) + s->world.boxes.count * 24;
    size_t ni = s->world.spheres.count * SEG * RINGS * 6 + s->world.boxes.count * 36;
    memset(sh, 0, sizeof *sh);
    sh->pos = calloc(nv + 1, sizeof(ak_vec3));
    sh->nrm = calloc(nv + 1, sizeof(ak_vec3));
    sh->idx = calloc(ni + 1, sizeof(uint32_t));
    if (!sh->pos || !sh->nrm || !sh->idx) return false;
    for (size_t k = 0; k < s->world.spheres.count; ++k) {
        const ak_particle_sphere* sp = &s->world.spheres.ptr[k];
        size_t base = sh->vcount;
        for (int i = 0; i <= RINGS; ++i)
            for (int j = 0; j <= SEG; ++j) {
                float th = AK_PI * (float)i / RINGS, ph = 2 * AK_PI * (float)j / SEG;
                ak_vec3 n = ak_vec3_make(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph));
                sh->nrm[sh->vcount] = n;
                sh->pos[sh->vcount++] = ak_vec3_madd(sp->center, n, sp->radius);
            }
        for (int i = 0; i < RINGS; ++i)
            for (int j = 0; j < SEG; ++j) {
                uint32_t a = (uint32_t)(base + (size_t)i * (SEG + 1) + (size_t)j), b = a + SEG + 1;
                uint32_t q[6] = {a, a + 1, b, a + 1, b + 1, b};
                for (int t = 0; t < 6; ++t) sh->idx[sh->icount++] = q[t];
            }
    }
    for (size_t k = 0; k < s->world.boxes.count; ++k) {
        const ak_particle_box* b = &s->world.boxes.ptr[k];
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                size_t base = sh->vcount;
                for (int c = 0; c < 4; ++c) {
                    float u = (c == 1 || c == 2) ? 1.0f : 0.0f, v = (c >= 2) ? 1.0f : 0.0f;
                    float f[3], lo[3] = {b->min.x, b->min.y, b->min.z},
                                hi[3] = {b->max.x, b->max.y, b->max.z};
                    f[axis] = side ? hi[axis] : lo[axis];
                    f[(axis + 1) % 3] =
                        lo[(axis + 1) % 3] + u * (hi[(axis + 1) % 3] - lo[(axis + 1) % 3]);
                    f[(axis + 2) % 3] =
                        lo[(axis + 2) % 3] + v * (hi[(axis + 2) % 3] - lo[(axis + 2) % 3]);
                    float n[3] = {0, 0, 0};
                    n[axis] = side ? 1.0f : -1.0f;
                    sh->pos[sh->vcount] = ak_vec3_make(f[0], f[1], f[2]);
                    sh->nrm[sh->vcount++] = ak_vec3_make(n[0], n[1], n[2]);
                }
                uint32_t q[6] = {0, 1, 2, 0, 2, 3};
                for (int t = 0; t < 6; ++t) sh->idx[sh->icount++] = (uint32_t)base + q[t];
            }
    }
    return true;
}

static void shapes_free(shapes* sh) {
    free(sh->pos);
    free(sh->nrm);
    free(sh->idx);
}

static void bounds_add(ak_vec3* lo, ak_vec3* hi, ak_vec3 p) {
    if (!(fabsf(p.x) < 1e6f && fabsf(p.y) < 1e6f && fabsf(p.z) < 1e6f)) return;
    *lo = ak_vec3_make(fminf(lo->x, p.x), fminf(lo->y, p.y), fminf(lo->z, p.z));
    *hi = ak_vec3_make(fmaxf(hi->x, p.x), fmaxf(hi->y, p.y), fmaxf(hi->z, p.z));
}

typedef struct renderer {
    cli_frame frame;
    bool framed;
    ak_image image;
    shapes sh;
    ak_vec4* colours;
    float ground;
    const char* title;
} renderer;

static int render_frame(renderer* rd, run* r, const ak_image* out) {
    cli_frame* f = &rd->frame;
    ak_raster* ras = f->raster;
    ak_raster_clear(ras, ak_vec4_make(0.83f, 0.87f, 0.93f, 1),
                    ak_vec4_make(0.48f, 0.51f, 0.58f, 1));
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
    ak_result res = ak_raster_draw_ground(ras, &f->camera, &g);
    for (size_t m = 0; res == AK_OK && m < mc; ++m)
        res = ak_raster_draw_mesh(ras, &f->camera, &meshes[m]);
    ak_particles_state st = ak_particles_get_state(r->ps);
    if (res == AK_OK && st.count) {
        /* sRGB-ish colours fading with age; radius from the mean size at the view distance. */
        double mean = 0.0;
        for (size_t i = 0; i < st.count; ++i) {
            float fade = isfinite(st.lifetime[i]) ? 1.0f - 0.6f * st.age[i] / st.lifetime[i] : 1.0f;
            ak_vec4 c = st.colour[i];
            rd->colours[i] = ak_vec4_make(c.x * fade, c.y * fade, c.z * fade, 1.0f);
            mean += st.size[i];
        }
        mean /= (double)st.count;
        ak_vec3 centre = ak_vec3_scale(ak_vec3_add(f->bmin, f->bmax), 0.5f);
        ak_vec3 a, b;
        float px = 2.0f;
        if (ak_raster_camera_project(&f->camera, f->width, f->height, centre, &a) &&
            ak_raster_camera_project(&f->camera, f->width, f->height,
                                     ak_vec3_add(centre, ak_vec3_make(0, (float)mean, 0)), &b))
            px = fabsf(a.y - b.y);
        ak_raster_points pts = {.positions = {st.position, st.count},
                                .colors = {rd->colours, st.count},
                                .radius = ak_clampf(px, 1.0f, 12.0f),
                                .outline = px > 3.0f ? 1.0f : 0.0f};
        res = ak_raster_draw_points(ras, &f->camera, &pts);
    }
    char title[160];
    snprintf(title, sizeof title, "%s  t=%.2fs  %zu particles", rd->title, ak_particles_time(r->ps),
             st.count);
    if (res == AK_OK)
        res = ak_raster_draw_text(ras, 10, 10, title, f->height >= 300 ? 2 : 1,
                                  ak_vec4_make(0.08f, 0.09f, 0.12f, 1));
    if (res == AK_OK) res = ak_raster_resolve(ras, out);
    return res == AK_OK ? CLI_OK : cli_fail("particles", "render: %s", ak_result_string(res));
}

/* ---- output --------------------------------------------------------------------------- */

static int write_json(const char* path, run* r, int steps) {
    FILE* f = fopen(path, "w");
    if (!f) return cli_fail("particles", "%s: cannot open for writing", path);
    ak_particles_state st = ak_particles_get_state(r->ps);
    fprintf(f, "{\"time\": %.9g, \"steps\": %d, \"particles\": [", ak_particles_time(r->ps), steps);
    for (size_t i = 0; i < st.count; ++i) {
        ak_vec3 p = st.position[i], v = st.velocity[i];
        fprintf(f, "%s\n  {\"p\": [%.9g, %.9g, %.9g], \"v\": [%.9g, %.9g, %.9g]}", i ? "," : "",
                (double)p.x, (double)p.y, (double)p.z, (double)v.x, (double)v.y, (double)v.z);
    }
    fprintf(f, "%s]}\n", st.count ? "\n" : "");
    if (fclose(f) != 0) return cli_fail("particles", "%s: write failed", path);
    return CLI_OK;
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
    if (preset && strcmp(preset, "fountain") && strcmp(preset, "rain") &&
        strcmp(preset, "fireworks") && strcmp(preset, "character"))
        return cli_usage("particles",
                         "--preset must be fountain, rain, fireworks or character, not '%s'",
                         preset);
    long steps = 200, seed = 1, threads = 1;
    if (CLI_GET(&a, "--steps") && !cli_parse_int(CLI_GET(&a, "--steps"), 0, 100000000, &steps))
        return cli_usage("particles", "--steps '%s' is not a whole number >= 0",
                         CLI_GET(&a, "--steps"));
    if (CLI_GET(&a, "--seed") && !cli_parse_int(CLI_GET(&a, "--seed"), 0, 2147483647L, &seed))
        return cli_usage("particles", "--seed '%s' is not a whole number >= 0",
                         CLI_GET(&a, "--seed"));
    if (CLI_GET(&a, "--threads") && !cli_parse_int(CLI_GET(&a, "--threads"), 1, 64, &threads))
        return cli_usage("particles", "--threads '%s' is not a whole number in 1..64",
                         CLI_GET(&a, "--threads"));
    float dt = 0.0f;
    if (CLI_GET(&a, "--dt") &&
        (!cli_parse_float(CLI_GET(&a, "--dt"), &dt) || !(dt > 0.0f) || dt > 10.0f))
        return cli_usage("particles", "--dt '%s' is not a number in (0, 10]", CLI_GET(&a, "--dt"));
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
    if (out && !gif && !cli_has_ext(out, ".png"))
        return cli_usage("particles", "output '%s' must end in .gif or .png", out);
    int width = 480, height = 360;
    if (CLI_GET(&a, "--size") && !cli_parse_size(CLI_GET(&a, "--size"), &width, &height))
        return cli_usage("particles", "--size '%s' is not WxH", CLI_GET(&a, "--size"));
    const char* json = CLI_GET(&a, "--json");

    particles_scene scene;
    if (preset) {
        if (!preset_scene(preset, &scene)) {
            particles_scene_free(&scene);
            return cli_fail("particles", "out of memory");
        }
    } else {
        cli_json j = {.file = a.pos[0]};
        cJSON* root = cli_json_load(&j, a.pos[0], 0);
        cJSON_Delete(root);
        if (!root) return cli_fail("particles", "%s", j.message);
        /* Read again as text for the parser (which wants memory, for the fuzzer). */
        FILE* f = fopen(a.pos[0], "rb");
        if (!f) return cli_fail("particles", "%s: cannot open the file", a.pos[0]);
        fseek(f, 0, SEEK_END);
        long size = ftell(f);
        fseek(f, 0, SEEK_SET);
        char* text = size >= 0 ? malloc((size_t)size + 1) : NULL;
        size_t got = text ? fread(text, 1, (size_t)size, f) : 0;
        fclose(f);
        if (!text || got != (size_t)size) {
            free(text);
            return cli_fail("particles", "%s: cannot read the file", a.pos[0]);
        }
        char err[600];
        bool ok = particles_scene_parse(a.pos[0], text, got, &scene, err, sizeof err);
        free(text);
        if (!ok) return cli_fail("particles", "%s", err);
    }
    if (dt > 0.0f) scene.dt = dt;
    if (integ != AK_INTEGRATOR_DEFAULT) scene.integrator = integ;

    character ch;
    bool use_char = preset && strcmp(preset, "character") == 0;
    memset(&ch, 0, sizeof ch);
    run r;
    memset(&r, 0, sizeof r);
    renderer rd;
    memset(&rd, 0, sizeof rd);
    ak_gif_writer* gw = NULL;
    if (use_char && character_init(&ch, &rc)) goto done;
    const int frames = gif ? (int)(steps < 100 ? steps : 100) : 1;
    const long every = gif && frames > 0 ? (steps + frames - 1) / frames : (steps > 0 ? steps : 1);
    if (out) {
        /* A dry run finds the bounds for a camera fixed over the whole animation. */
        if ((rc = run_init(&r, &scene, use_char ? &ch : NULL, (uint64_t)seed, (uint32_t)threads)))
            goto done;
        ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
        for (size_t k = 0; k < scene.world.spheres.count; ++k) {
            const ak_particle_sphere* s = &scene.world.spheres.ptr[k];
            bounds_add(&lo, &hi, ak_vec3_sub(s->center, ak_vec3_splat(s->radius)));
            bounds_add(&lo, &hi, ak_vec3_add(s->center, ak_vec3_splat(s->radius)));
        }
        for (size_t k = 0; k < scene.world.boxes.count; ++k) {
            bounds_add(&lo, &hi, scene.world.boxes.ptr[k].min);
            bounds_add(&lo, &hi, scene.world.boxes.ptr[k].max);
        }
        for (size_t k = 0; k < scene.emitter_count; ++k)
            bounds_add(&lo, &hi, scene.emitters[k].center);
        for (long s = 0; s <= steps; ++s) {
            if (s > 0 && (rc = run_step(&r, (int)s - 1))) goto done;
            if (s % every && s != steps) continue;
            ak_particles_state st = ak_particles_get_state(r.ps);
            for (size_t i = 0; i < st.count; i += 1 + st.count / 4000)
                bounds_add(&lo, &hi, st.position[i]);
            if (use_char)
                for (size_t v = 0; v < ch.vertex_count; v += 7)
                    bounds_add(&lo, &hi, ch.positions[v]);
        }
        run_free(&r);
        memset(&r, 0, sizeof r);
        if (!(lo.x <= hi.x)) lo = ak_vec3_splat(-1), hi = ak_vec3_splat(1);
        rd.ground = lo.y;
        for (size_t k = 0; k < scene.world.planes.count; ++k) {
            ak_vec3 n = ak_vec3_normalize(scene.world.planes.ptr[k].normal);
            if (n.y > 0.99f)
                rd.ground = scene.world.planes.ptr[k].d / n.y, lo.y = fminf(lo.y, rd.ground);
        }
        if (use_char && character_pose(&ch, 0.0f, 0.0f) != AK_OK) {
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
        if (!rd.colours || !shapes_build(&rd.sh, &scene)) {
            rc = cli_fail("particles", "out of memory");
            goto done;
        }
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
    if ((rc = run_init(&r, &scene, use_char ? &ch : NULL, (uint64_t)seed, (uint32_t)threads)))
        goto done;
    for (long s = 0; s <= steps; ++s) {
        if (s > 0 && (rc = run_step(&r, (int)s - 1))) goto done;
        cli_progress("particles", (size_t)s, (size_t)steps);
        if (gw && (s % every == 0 || s == steps)) {
            if ((rc = render_frame(&rd, &r, &rd.image))) goto done;
            ak_result res = ak_gif_writer_add_frame(gw, &rd.image);
            if (res != AK_OK) {
                rc = cli_fail("particles", "%s: %s", out, ak_result_string(res));
                goto done;
            }
        }
    }
    if (json && (rc = write_json(json, &r, (int)steps))) goto done;
    if (out && !gif) {
        if ((rc = render_frame(&rd, &r, &rd.image))) goto done;
        ak_result res = ak_png_write(out, &rd.image);
        if (res != AK_OK) rc = cli_fail("particles", "%s: %s", out, ak_result_string(res));
    }
done:
    if (gw) {
        ak_result res = ak_gif_writer_finish(gw);
        if (rc == CLI_OK && res != AK_OK)
            rc = cli_fail("particles", "%s: %s", out, ak_result_string(res));
    }
    run_free(&r);
    if (rd.framed) cli_frame_free(&rd.frame);
    free(rd.image.pixels);
    free(rd.colours);
    shapes_free(&rd.sh);
    if (use_char) character_free(&ch);
    particles_scene_free(&scene);
    return rc;
}
