/* A particle run shared by `animkit particles` and `animkit view` (particles_run.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "particles_run.h"
#include "render.h"

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

/* Rain: emitter_base falling straight down (a narrow cone) from a flat box. */
static ak_particle_emitter rain_base(ak_vec3 center, ak_vec3 half_extents) {
    ak_particle_emitter e = emitter_base();
    e.shape = AK_EMITTER_BOX, e.center = center, e.half_extents = half_extents;
    e.direction = ak_vec3_make(0, -1, 0), e.cone_angle = 0.02f;
    return e;
}

/* Fills s for a preset; false when out of memory. */
bool particles_preset(const char* name, particles_scene* s) {
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
    particles_sprites* look = &s->sprites;
    if (strcmp(name, "fountain") == 0) {
        /* droplets of 6 mm radius (they were 3 cm: 4500 touching balls read as one blob) */
        e.center = ak_vec3_make(0, 0.05f, 0);
        e.size_min = 0.005f, e.size_max = 0.007f;
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
        e = rain_base(ak_vec3_make(0, 4, 0), ak_vec3_make(2, 0.1f, 2));
        e.speed_min = 3, e.speed_max = 4;
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
        e = rain_base(ak_vec3_make(0, 2.6f, 0), ak_vec3_make(0.7f, 0.05f, 0.7f));
        e.speed_min = 2, e.speed_max = 2.5f;
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
    } else if (strcmp(name, "fire") == 0) {
        /* Flames: additive puffs rising from a disc, hot yellow to red to nothing while they
         * shrink, buoyant (gravity up) and slowed by the air; each puff plays a 4x4 sheet. */
        e.shape = AK_EMITTER_DISC, e.radius = 0.22f, e.center = ak_vec3_make(0, 0.02f, 0);
        e.cone_angle = 0.2f, e.speed_min = 0.8f, e.speed_max = 1.4f;
        e.lifetime_min = 0.6f, e.lifetime_max = 1.1f, e.size_min = 0.08f, e.size_max = 0.12f;
        e.colour = ak_vec4_make(1.0f, 0.62f, 0.22f, 1), e.rate = 350.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->world.gravity = ak_vec3_make(0, 2.0f, 0);
        s->world.drag_linear = 0.8f;
        look->enabled = true, look->texture = AK_SPRITE_TEXTURE_PUFF, look->sheet_columns = 4, look->sheet_rows = 4;
        look->blend = AK_BLEND_ADD;
        look->look = (ak_particle_look){
            .colour_keys = {{0.0f, {1.0f, 1.0f, 0.75f, 0.3f}},
                            {0.3f, {1.0f, 0.75f, 0.45f, 0.3f}},
                            {0.7f, {0.9f, 0.35f, 0.25f, 0.2f}},
                            {1.0f, {0.5f, 0.2f, 0.2f, 0.0f}}},
            .colour_key_count = 4,
            .size_keys = {{0.0f, 0.7f}, {0.35f, 1.0f}, {1.0f, 0.35f}},
            .size_key_count = 3,
            .frame_count = 16};
    } else if (strcmp(name, "smoke") == 0) {
        /* Smoke: few large puffs drifting up and downwind, fading in then out while they grow
         * and lighten; alpha-blended back to front. */
        e.shape = AK_EMITTER_DISC, e.radius = 0.12f, e.center = ak_vec3_make(0, 0.05f, 0);
        e.cone_angle = 0.3f, e.speed_min = 0.5f, e.speed_max = 0.8f;
        e.lifetime_min = 3.0f, e.lifetime_max = 4.0f, e.size_min = 0.12f, e.size_max = 0.18f;
        e.colour = ak_vec4_make(0.42f, 0.42f, 0.45f, 1), e.rate = 40.0f;
        s->emitters[0] = e;
        s->emitter_count = 1;
        s->world.gravity = ak_vec3_make(0, 0.25f, 0);
        s->world.wind = ak_vec3_make(0.5f, 0, 0);
        s->world.drag_linear = 0.6f;
        look->enabled = true, look->texture = AK_SPRITE_TEXTURE_PUFF, look->sheet_columns = 4, look->sheet_rows = 2;
        look->blend = AK_BLEND_ALPHA;
        look->look = (ak_particle_look){
            .colour_keys = {{0.0f, {0.8f, 0.8f, 0.8f, 0.0f}},
                            {0.1f, {1.0f, 1.0f, 1.0f, 0.75f}},
                            {1.0f, {1.9f, 1.9f, 1.9f, 0.0f}}},
            .colour_key_count = 3,
            .size_keys = {{0.0f, 0.6f}, {1.0f, 3.0f}},
            .size_key_count = 2,
            .frame_count = 8,
            .frame_rate = 2.0f};
    } else {
        return false;
    }
    return true;
}

const char* const particles_preset_names = "fountain, rain, fireworks, character, fire or smoke";

bool particles_preset_known(const char* name) {
    static const char* const names[] = {"fountain", "rain", "fireworks", "character", "fire", "smoke"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k)
        if (name && strcmp(name, names[k]) == 0) return true;
    return false;
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


int particles_run_init(particles_run* r, particles_scene* s, particles_character* ch, uint64_t seed, uint32_t threads) {
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
    r->fired = calloc(s->emitter_count + 1, sizeof(uint64_t));
    r->springs = calloc(s->world.springs.count + 1, sizeof(ak_particle_spring));
    if (!r->fired || !r->springs) return cli_fail("particles", "out of memory");
    for (size_t e = 0; e < s->emitter_count; ++e) s->emitters[e].carry = 0.0;
    r->world = s->world;
    if (s->world.springs.count)
        memcpy(r->springs, s->world.springs.ptr, s->world.springs.count * sizeof *r->springs);
    r->world.springs.ptr = r->springs;
    r->file_alive = s->particle_count;
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

/* How many bursts (start + k interval, k = 0, 1, ...) are due before t1: the smallest k >= fired
 * with start + k interval >= t1, saturating at 2^53 (where a double stops counting by one).
 * A bounded number of operations whatever the interval. */
static uint64_t bursts_due(float start, float interval, double t1, uint64_t fired) {
    const double limit = 9007199254740992.0; /* 2^53 */
    double k = ceil((t1 - (double)start) / (double)interval);
    if (!(k < limit)) k = limit;
    if (k < (double)fired) k = (double)fired;
    for (int i = 0; i < 4 && k > (double)fired && (double)start + (k - 1.0) * (double)interval >= t1; ++i) k -= 1.0;
    for (int i = 0; i < 4 && k < limit && (double)start + k * (double)interval < t1; ++i) k += 1.0;
    return (uint64_t)k;
}

/* One step: pose the character for the end of the step, emit, step. */
int particles_run_step(particles_run* r, int step) {
    particles_scene* s = r->scene;
    const float dt = s->dt;
    const double t1 = (double)(step + 1) * dt;
    ak_result res = AK_OK;
    if (r->ch) res = particles_character_pose(r->ch, (float)t1, dt);
    for (size_t e = 0; e < s->emitter_count && res == AK_OK; ++e) {
        res = ak_particles_emit(r->ps, &s->emitters[e], dt, NULL);
        /* Bursts due before the end of this step (start, start + interval, ...). The loop is
         * bounded by integers: at most capacity + 1 calls per emitter and step (each call adds
         * a particle until the system is full); the bursts still due after that are counted,
         * not fired, in a bounded number of operations. A 1e-30 s interval used to hang here:
         * the count was stepped with k -= 1.0 on a double near 1e28, which no longer changes. */
        const particles_burst* b = &s->bursts[e];
        const uint64_t max_calls = (uint64_t)ak_particles_capacity(r->ps) + 1u;
        uint64_t calls = 0;
        while (res == AK_OK && b->count > 0 && (b->interval > 0.0f || r->fired[e] == 0)) {
            if ((double)b->start + (double)r->fired[e] * (double)b->interval >= t1) break;
            if (b->interval > 0.0f && (ak_particles_count(r->ps) >= ak_particles_capacity(r->ps) || calls >= max_calls)) {
                /* full: every burst still due this step would be dropped (a full system emits
                 * nothing and draws no random numbers), so count them without calling */
                r->fired[e] = bursts_due(b->start, b->interval, t1, r->fired[e]);
                break;
            }
            res = ak_particles_burst(r->ps, &s->emitters[e], b->count, NULL);
            ++r->fired[e];
            ++calls;
        }
    }
    if (res == AK_OK) res = ak_particles_step(r->ps, &r->world, dt);
    if (res == AK_ERR_BUDGET)
        return cli_fail("particles",
                        "step %d: Lennard-Jones needs more than %.3g distance tests per force evaluation (particles "
                        "packed into few cells of the %g m cut-off); lower lennard_jones.cutoff or sigma, or spread "
                        "the particles out",
                        step, (double)AK_PARTICLES_LJ_DEFAULT_PAIR_TESTS,
                        (double)(r->world.lennard_jones.cutoff > 0.0f ? r->world.lennard_jones.cutoff
                                                                       : 2.5f * r->world.lennard_jones.sigma));
    if (res != AK_OK) return cli_fail("particles", "step %d: %s", step, ak_result_string(res));
    /* File particles come first and keep their order (ids 0.. in file order); when some die
     * (a lifetime, or a state that stopped being finite) the springs follow the survivors'
     * new indices and springs to a dead particle go (they used to point past the end: the
     * next step failed with "an index is out of range") */
    const ak_particles_state st = ak_particles_get_state(r->ps);
    size_t alive = 0;
    while (alive < st.count && st.id[alive] < s->particle_count) ++alive;
    if (alive != r->file_alive && s->world.springs.count) {
        uint32_t* where = malloc(s->particle_count * sizeof *where);
        if (!where) return cli_fail("particles", "out of memory");
        for (size_t i = 0; i < s->particle_count; ++i) where[i] = UINT32_MAX;
        for (size_t i = 0; i < alive; ++i) where[st.id[i]] = (uint32_t)i;
        size_t n = 0;
        for (size_t k = 0; k < s->world.springs.count; ++k) {
            ak_particle_spring sp = s->world.springs.ptr[k];
            if (where[sp.i] == UINT32_MAX || where[sp.j] == UINT32_MAX) continue;
            sp.i = where[sp.i], sp.j = where[sp.j];
            r->springs[n++] = sp;
        }
        r->world.springs.count = n;
        free(where);
    }
    r->file_alive = alive;
    return CLI_OK;
}

void particles_run_free(particles_run* r) {
    ak_particles_destroy(r->ps);
    free(r->fired);
    free(r->springs);
}


/* UV spheres and boxes of the colliders as one triangle mesh. */
bool particles_shapes_build(particles_shapes* sh, const particles_scene* s) {
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

int particles_sprites_init(particles_sprite_renderer* sr, const particles_scene* s, const char* command) {
    memset(sr, 0, sizeof *sr);
    const particles_sprites* sp = &s->sprites;
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

ak_result particles_draw_sprites(ak_raster* ras, const ak_raster_camera* camera, const particles_scene* s,
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

bool particles_dark_sky(const particles_scene* s, ak_vec4* top, ak_vec4* bottom) {
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
