/* A particle run shared by `animkit particles` and `animkit view` (particles_run.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "particles_run.h"
#include "render.h"

bool particles_preset_known(const char* name) {
    if (!name) return false;
    ak_particles_scene s;
    ak_diag diag;
    const ak_result res = ak_particles_scene_preset(name, &s, &diag);
    ak_particles_scene_free(&s);
    return res != AK_ERR_NOT_FOUND;
}

/* ---- the character ----------------------------------------------------------------------- */


static void character_gather(particles_character* c) {
    size_t v = 0;
    for (size_t m = 0; m < c->scene->mesh_count; ++m) {
        const ak_mesh* mesh = c->scene->meshes[m].mesh;
        if (!mesh) continue;
        memcpy(c->positions + v, c->poser.positions[m], mesh->vertex_count * sizeof(ak_vec3));
        v += mesh->vertex_count;
    }
}

int particles_character_init(particles_character* c, int* rc) {
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
ak_result particles_character_pose(particles_character* c, float t, float elapsed) {
    ak_result r = cli_poser_pose(&c->poser, 0, t, false, CLI_LBS);
    if (r != AK_OK) return r;
    character_gather(c);
    return ak_particle_mesh_update(c->collider, (ak_vec3_cspan){c->positions, c->vertex_count},
                                   elapsed);
}

void particles_character_free(particles_character* c) {
    if (c->posed) cli_poser_free(&c->poser);
    ak_particle_mesh_destroy(c->collider);
    free(c->positions);
    free(c->indices);
    free(c->cdf);
    ak_scene_destroy(c->scene);
}

/* ---- simulation ------------------------------------------------------------------------ */


/* The library's "particles: problem" without its prefix (the command says "animkit particles:"). */
static const char* lib_message(const ak_diag* d) {
    return strncmp(d->message, "particles: ", 11) == 0 ? d->message + 11 : d->message;
}

int particles_run_init(particles_run* r, ak_particles_scene* s, particles_character* ch, uint64_t seed, uint32_t threads) {
    memset(r, 0, sizeof *r);
    r->ch = ch;
    ak_particles_scene_run_desc d = {.seed = seed, .thread_count = threads};
    if (ch) {
        d.mesh_collider = ch->collider;
        d.mesh_positions = (ak_vec3_cspan){ch->positions, ch->vertex_count};
        d.mesh_indices = (ak_u32_cspan){ch->indices, ch->index_count};
        d.mesh_area_cdf = (ak_f32_span){ch->cdf, ch->index_count / 3};
    }
    ak_diag diag;
    const ak_result res = ak_particles_scene_run_init(&r->lib, s, &d, &diag);
    r->ps = r->lib.system;
    return res == AK_OK ? CLI_OK : cli_fail("particles", "%s", lib_message(&diag));
}

/* One step: pose the character for the end of the step, then the library's step (emit, fire
 * bursts, step, re-index springs). */
int particles_run_step(particles_run* r, int step) {
    const float dt = r->lib.scene->dt;
    ak_result res = AK_OK;
    r->lib.step_index = step;
    if (r->ch) res = particles_character_pose(r->ch, (float)((double)(step + 1) * dt), dt);
    if (res != AK_OK) return cli_fail("particles", "step %d: %s", step, ak_result_string(res));
    ak_diag diag;
    if (ak_particles_scene_run_step(&r->lib, &diag) != AK_OK)
        return cli_fail("particles", "%s", lib_message(&diag));
    return CLI_OK;
}

void particles_run_free(particles_run* r) {
    ak_particles_scene_run_free(&r->lib);
    r->ps = NULL;
}


/* UV spheres and boxes of the colliders as one triangle mesh. */
bool particles_shapes_build(particles_shapes* sh, const ak_particles_scene* s) {
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

void particles_shapes_free(particles_shapes* sh) {
    free(sh->pos);
    free(sh->nrm);
    free(sh->idx);
}

void particles_bounds_add(ak_vec3* lo, ak_vec3* hi, ak_vec3 p) {
    if (!(fabsf(p.x) < 1e6f && fabsf(p.y) < 1e6f && fabsf(p.z) < 1e6f)) return;
    *lo = ak_vec3_make(fminf(lo->x, p.x), fminf(lo->y, p.y), fminf(lo->z, p.z));
    *hi = ak_vec3_make(fmaxf(hi->x, p.x), fmaxf(hi->y, p.y), fmaxf(hi->z, p.z));
}
ak_result particles_draw_points(ak_raster* ras, const ak_raster_camera* camera, int width, int height, ak_vec3 centre,
                                ak_particles* ps, ak_vec4* colours) {
    ak_particles_state st = ak_particles_get_state(ps);
    if (!st.count) return AK_OK;
    /* sRGB-ish colours fading with age; radius from the mean size at the view distance. */
    double mean = 0.0;
    for (size_t i = 0; i < st.count; ++i) {
        float fade = isfinite(st.lifetime[i]) ? 1.0f - 0.6f * st.age[i] / st.lifetime[i] : 1.0f;
        ak_vec4 c = st.colour[i];
        colours[i] = ak_vec4_make(c.x * fade, c.y * fade, c.z * fade, 1.0f);
        mean += st.size[i];
    }
    mean /= (double)st.count;
    ak_vec3 a, b;
    float px = 2.0f;
    if (ak_raster_camera_project(camera, width, height, centre, &a) &&
        ak_raster_camera_project(camera, width, height, ak_vec3_add(centre, ak_vec3_make(0, (float)mean, 0)), &b))
        px = fabsf(a.y - b.y);
    ak_raster_points pts = {.positions = {st.position, st.count},
                            .colors = {colours, st.count},
                            .radius = ak_clampf(px, 1.0f, 12.0f),
                            .outline = px > 3.0f ? 1.0f : 0.0f};
    return ak_raster_draw_points(ras, camera, &pts);
}

/* ---- sprites ------------------------------------------------------------------------------- */

int particles_sprites_init(particles_sprite_renderer* sr, const ak_particles_scene* s, const char* command) {
    memset(sr, 0, sizeof *sr);
    const ak_particles_scene_sprites* sp = &s->sprites;
    if (!sp->enabled) return CLI_OK;
    const size_t cap = (size_t)s->capacity + 1;
    sr->sizes = calloc(cap, sizeof *sr->sizes);
    sr->colours = calloc(cap, sizeof *sr->colours);
    sr->frames = calloc(cap, sizeof *sr->frames);
    sr->order = calloc(cap, sizeof *sr->order);
    sr->depth = calloc(cap, sizeof *sr->depth);
    if (!sr->sizes || !sr->colours || !sr->frames || !sr->order || !sr->depth) return cli_fail(command, "out of memory");
    const int cols = sp->sheet_columns > 0 ? sp->sheet_columns : 1, rows = sp->sheet_rows > 0 ? sp->sheet_rows : 1;
    if (sp->sheet_path) {
        int w = 0, h = 0;
        ak_result res = ak_png_info(sp->sheet_path, &w, &h);
        if (res == AK_OK && ((double)w * (double)h > 4096.0 * 4096.0 || w < cols || h < rows))
            return cli_fail(command, "%s: a %dx%d sprite sheet cannot hold %dx%d frames of at least 1 pixel (at most 4096x4096)",
                            sp->sheet_path, w, h, cols, rows);
        if (res == AK_OK) {
            sr->texture = (ak_image){.pixels = malloc((size_t)w * (size_t)h * 4u), .width = w, .height = h};
            res = sr->texture.pixels ? ak_png_read(sp->sheet_path, &sr->texture) : AK_ERR_NO_MEMORY;
        }
        if (res != AK_OK) return cli_fail(command, "%s: cannot read the sprite sheet: %s", sp->sheet_path, ak_result_string(res));
    } else {
        /* a sheet of built-in textures, one seed per frame: 64 x 64 pixels each, smaller for
         * sheets of more than 16 frames a side (the sheet stays within 1024 x 1024, 4 MiB) */
        const int side = cols > rows ? cols : rows, fw = side > 16 ? 1024 / side : 64;
        sr->texture = (ak_image){.pixels = malloc((size_t)(cols * fw) * (size_t)(rows * fw) * 4u),
                                 .width = cols * fw, .height = rows * fw};
        if (!sr->texture.pixels) return cli_fail(command, "out of memory");
        for (int f = 0; f < cols * rows; ++f) {
            ak_image cell = {.pixels = ak_image_pixel(&sr->texture, (f % cols) * fw, (f / cols) * fw),
                             .width = fw,
                             .height = fw,
                             .stride = (size_t)sr->texture.width * 4u};
            ak_sprite_texture_generate(sp->texture, (uint32_t)f * 7919u + 1u, &cell);
        }
    }
    sr->columns = cols, sr->rows = rows;
    sr->ready = true;
    return CLI_OK;
}

ak_result particles_draw_sprites(ak_raster* ras, const ak_raster_camera* camera, const ak_particles_scene* s,
                                 particles_sprite_renderer* sr, ak_particles* ps) {
    ak_particles_state st = ak_particles_get_state(ps);
    if (!st.count || !sr->ready) return AK_OK;
    const ak_particle_look* look = &s->sprites.look;
    for (size_t i = 0; i < st.count; ++i) {
        const ak_vec4 k = ak_particle_look_colour(look, st.age[i], st.lifetime[i]), c = st.colour[i];
        sr->colours[i] = ak_vec4_make(c.x * k.x, c.y * k.y, c.z * k.z, c.w * k.w);
        sr->sizes[i] = 2.0f * st.size[i] * ak_particle_look_size(look, st.age[i], st.lifetime[i]);
        sr->frames[i] = ak_particle_look_frame(look, st.age[i], st.lifetime[i]);
    }
    const ak_blend blend = s->sprites.blend == AK_BLEND_ADD || s->sprites.blend == AK_BLEND_OPAQUE ? s->sprites.blend
                                                                                                 : AK_BLEND_ALPHA;
    ak_raster_sprites d = {.positions = {st.position, st.count},
                           .sizes = {sr->sizes, st.count},
                           .colors = {sr->colours, st.count},
                           .frames = {sr->frames, st.count},
                           .texture = &sr->texture,
                           .sheet_columns = sr->columns,
                           .sheet_rows = sr->rows,
                           .blend = blend};
    if (blend == AK_BLEND_ALPHA) { /* additive blending and depth-tested cut-outs do not depend on the order */
        ak_result res = ak_raster_sprites_sort(camera, (ak_vec3_cspan){st.position, st.count},
                                               (ak_f32_span){sr->depth, st.count}, (ak_u32_span){sr->order, st.count});
        if (res != AK_OK) return res;
        d.order = (ak_u32_cspan){sr->order, st.count};
    }
    return ak_raster_draw_sprites(ras, camera, &d);
}

bool particles_dark_sky(const ak_particles_scene* s, ak_vec4* top, ak_vec4* bottom) {
    if (!s->sprites.enabled || s->sprites.blend != AK_BLEND_ADD) return false;
    *top = ak_vec4_make(0.05f, 0.06f, 0.10f, 1), *bottom = ak_vec4_make(0.16f, 0.16f, 0.20f, 1);
    return true;
}

void particles_sprites_free(particles_sprite_renderer* sr) {
    free(sr->sizes);
    free(sr->colours);
    free(sr->frames);
    free(sr->order);
    free(sr->depth);
    free(sr->texture.pixels);
    memset(sr, 0, sizeof *sr);
}
