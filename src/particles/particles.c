/* Particle systems: SoA state, emitters, forces, four integrators, continuous collisions. */
#include <animkit/particles.h>

#include <math.h>

#include "tasks.h"
#include "internal.h"
#include "simd.h"

#define PS_MAX_THREADS 64u
#define PS_MIN_PER_THREAD 8192u /* below this a thread start costs more than it saves */
#define PS_MAX_CAPACITY (1u << 30)
#define PS_CONTACT_ITERATIONS 4
#define PS_MESH_OFFSET 1e-5f /* mesh contacts leave particles this far off the surface */
#define PS_EMIT_OFFSET 1e-4f /* mesh emission starts this far out along the triangle normal */

struct ak_particles {
    ak_allocator alloc;
    bool has_alloc;
    uint32_t capacity;
    uint32_t thread_count;
    ak_particles_integrator integrator;
    size_t count;
    uint32_t next_id;
    double time;
    ak_rng rng;
    /* state */
    ak_vec3 *pos, *vel, *force;
    float *inv_mass, *age, *life, *size;
    ak_vec4* colour;
    uint32_t* id;
    /* integrator scratch */
    ak_vec3 *x0, *v0, *acc, *xs, *vs, *sx, *sv;
    uint8_t* grid_mem;
    size_t grid_mem_size;
};

struct ak_particle_mesh {
    ak_allocator alloc;
    bool has_alloc;
    size_t vertex_count, tri_count;
    uint32_t* indices;
    ak_vec3* verts;
    ak_vec3* vel;     /* vertex velocities from the last update */
    ak_vec3* tri_vel; /* mean vertex velocity of each triangle */
    ak_vec3* centroid;
    float reach;     /* largest distance from a centroid to its triangle's corners */
    float max_speed; /* largest triangle speed */
    float restitution, friction;
    ak_grid grid;
    uint8_t* grid_mem;
    size_t grid_mem_size;
};

/* ---- small helpers ------------------------------------------------------------------ */

static inline bool finite3(ak_vec3 v) {
    return ak_finitef(v.x) && ak_finitef(v.y) && ak_finitef(v.z);
}
static inline bool finite4(ak_vec4 v) {
    return ak_finitef(v.x) && ak_finitef(v.y) && ak_finitef(v.z) && ak_finitef(v.w);
}

static inline ak_vec3 unit_or_up(ak_vec3 v) {
    ak_vec3 n = ak_vec3_normalize(v);
    return ak_vec3_length_sq(n) > 0.0f ? n : ak_vec3_make(0.0f, 1.0f, 0.0f);
}

/* Two unit vectors completing n to a right-handed orthonormal frame. */
static void basis(ak_vec3 n, ak_vec3* t, ak_vec3* b) {
    ak_vec3 a = fabsf(n.x) < 0.9f ? ak_vec3_make(1, 0, 0) : ak_vec3_make(0, 1, 0);
    *t = ak_vec3_normalize(ak_vec3_cross(a, n));
    *b = ak_vec3_cross(n, *t);
}

/* A pass over particles [begin, end); returns true when one of them is now dead (age >=
 * lifetime or non-finite), so the step knows whether to compact. */
typedef bool (*range_fn)(void* ctx, size_t begin, size_t end);

typedef struct range_task {
    range_fn fn;
    void* ctx;
    size_t begin, end;
    bool dead;
} range_task;

static void* range_thread(void* arg) {
    range_task* t = (range_task*)arg;
    t->dead = t->fn(t->ctx, t->begin, t->end);
    return NULL;
}

/* Runs fn over [0, n) split in contiguous ranges. Each element's work is independent of the
 * split, so results do not depend on the thread count. */
static bool parallel_for(uint32_t threads, size_t n, range_fn fn, void* ctx) {
    size_t most = n / PS_MIN_PER_THREAD;
    if (threads > most) threads = most ? (uint32_t)most : 1;
    if (threads <= 1) return fn(ctx, 0, n);
    range_task tasks[PS_MAX_THREADS];
    for (uint32_t t = 0; t < threads; ++t)
        tasks[t] = (range_task){fn, ctx, n * t / threads, n * (t + 1) / threads, false};
    akp_run_tasks(range_thread, tasks, sizeof(range_task), threads);
    bool dead = false;
    for (uint32_t t = 0; t < threads; ++t) dead = dead || tasks[t].dead;
    return dead;
}

/* ---- lifecycle ---------------------------------------------------------------------- */

ak_particles_desc ak_particles_desc_resolved(const ak_particles_desc* desc) {
    ak_particles_desc d = {0};
    if (desc) d = *desc;
    if (d.integrator == AK_INTEGRATOR_DEFAULT) d.integrator = AK_INTEGRATOR_SYMPLECTIC;
    if (d.thread_count == 0) d.thread_count = 1;
    return d;
}

typedef struct ps_layout {
    size_t pos, vel, force, inv_mass, age, life, size, colour, id, x0, v0, acc, xs, vs, sx, sv,
        grid, total;
} ps_layout;

static ps_layout ps_carve(size_t cap, size_t grid_size) {
    ps_layout l;
    size_t off = akp_align16(sizeof(ak_particles));
    const size_t v3 = akp_align16(cap * sizeof(ak_vec3)), f = akp_align16(cap * sizeof(float));
    l.pos = off, off += v3;
    l.vel = off, off += v3;
    l.force = off, off += v3;
    l.inv_mass = off, off += f;
    l.age = off, off += f;
    l.life = off, off += f;
    l.size = off, off += f;
    l.colour = off, off += akp_align16(cap * sizeof(ak_vec4));
    l.id = off, off += akp_align16(cap * sizeof(uint32_t));
    l.x0 = off, off += v3;
    l.v0 = off, off += v3;
    l.acc = off, off += v3;
    l.xs = off, off += v3;
    l.vs = off, off += v3;
    l.sx = off, off += v3;
    l.sv = off, off += v3;
    l.grid = off, off += akp_align16(grid_size);
    l.total = off;
    return l;
}

ak_result ak_particles_create(const ak_particles_desc* desc, const ak_allocator* alloc,
                              ak_particles** out_particles) {
    if (out_particles) *out_particles = NULL;
    if (!desc || !out_particles) return AK_ERR_NULL_ARG;
    ak_particles_desc d = ak_particles_desc_resolved(desc);
    if (d.capacity == 0 || d.capacity > PS_MAX_CAPACITY ||
        (unsigned)d.integrator >= AK_INTEGRATOR_COUNT || d.thread_count > PS_MAX_THREADS)
        return AK_ERR_BAD_ARG;
    ak_grid_desc gd = {.cell_size = 1.0f};
    const size_t grid_size = ak_grid_memory_size(d.capacity, &gd);
    ps_layout l = ps_carve(d.capacity, grid_size);
    uint8_t* mem = (uint8_t*)akp_calloc(alloc, l.total);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_particles* ps = (ak_particles*)(void*)mem;
    if (alloc) ps->alloc = *alloc, ps->has_alloc = true;
    ps->capacity = d.capacity;
    ps->thread_count = d.thread_count;
    ps->integrator = d.integrator;
    ps->rng = ak_rng_make(d.seed);
#define PS_AT(field, type) ps->field = (type*)(void*)(mem + l.field)
    PS_AT(pos, ak_vec3);
    PS_AT(vel, ak_vec3);
    PS_AT(force, ak_vec3);
    PS_AT(inv_mass, float);
    PS_AT(age, float);
    PS_AT(life, float);
    PS_AT(size, float);
    PS_AT(colour, ak_vec4);
    PS_AT(id, uint32_t);
    PS_AT(x0, ak_vec3);
    PS_AT(v0, ak_vec3);
    PS_AT(acc, ak_vec3);
    PS_AT(xs, ak_vec3);
    PS_AT(vs, ak_vec3);
    PS_AT(sx, ak_vec3);
    PS_AT(sv, ak_vec3);
#undef PS_AT
    ps->grid_mem = mem + l.grid;
    ps->grid_mem_size = grid_size;
    *out_particles = ps;
    return AK_OK;
}

void ak_particles_destroy(ak_particles* particles) {
    if (!particles) return;
    ak_allocator a = particles->alloc;
    akp_free(particles->has_alloc ? &a : NULL, particles);
}

ak_particles_state ak_particles_get_state(ak_particles* ps) {
    ak_particles_state s = {0};
    if (!ps) return s;
    s.count = ps->count;
    s.position = ps->pos;
    s.velocity = ps->vel;
    s.force = ps->force;
    s.inv_mass = ps->inv_mass;
    s.age = ps->age;
    s.lifetime = ps->life;
    s.size = ps->size;
    s.colour = ps->colour;
    s.id = ps->id;
    return s;
}

size_t ak_particles_count(const ak_particles* ps) { return ps ? ps->count : 0; }
size_t ak_particles_capacity(const ak_particles* ps) { return ps ? ps->capacity : 0; }
double ak_particles_time(const ak_particles* ps) { return ps ? ps->time : 0.0; }

ak_result ak_particles_set_integrator(ak_particles* ps, ak_particles_integrator integrator) {
    if (!ps) return AK_ERR_NULL_ARG;
    if ((unsigned)integrator >= AK_INTEGRATOR_COUNT) return AK_ERR_BAD_ARG;
    ps->integrator = integrator == AK_INTEGRATOR_DEFAULT ? AK_INTEGRATOR_SYMPLECTIC : integrator;
    return AK_OK;
}

static inline ak_vec4 colour_or_white(ak_vec4 c) {
    return (c.x == 0.0f && c.y == 0.0f && c.z == 0.0f && c.w == 0.0f) ? ak_vec4_make(1, 1, 1, 1)
                                                                      : c;
}

static void push(ak_particles* ps, ak_vec3 p, ak_vec3 v, float inv_mass, float life, float size,
                 ak_vec4 colour) {
    size_t i = ps->count++;
    ps->pos[i] = p;
    ps->vel[i] = v;
    ps->force[i] = ak_vec3_zero();
    ps->inv_mass[i] = inv_mass;
    ps->age[i] = 0.0f;
    ps->life[i] = life;
    ps->size[i] = size;
    ps->colour[i] = colour;
    ps->id[i] = ps->next_id++;
}

ak_result ak_particles_add(ak_particles* ps, const ak_particle_init* init, size_t* out_index) {
    if (!ps || !init) return AK_ERR_NULL_ARG;
    if (!finite3(init->position) || !finite3(init->velocity) || !finite4(init->colour) ||
        !ak_finitef(init->mass) || init->mass < 0.0f || !(init->lifetime >= 0.0f) ||
        !ak_finitef(init->size) || init->size < 0.0f)
        return AK_ERR_BAD_DATA;
    if (ps->count >= ps->capacity) return AK_ERR_SPAN_SMALL;
    if (out_index) *out_index = ps->count;
    push(ps, init->position, init->velocity, init->mass > 0.0f ? 1.0f / init->mass : 0.0f,
         init->lifetime > 0.0f ? init->lifetime : INFINITY, init->size > 0.0f ? init->size : 0.05f,
         colour_or_white(init->colour));
    return AK_OK;
}

void ak_particles_clear(ak_particles* ps) {
    if (ps) ps->count = 0;
}

/* ---- emitters ----------------------------------------------------------------------- */

static ak_result emitter_check(const ak_particle_emitter* e) {
    if ((unsigned)e->shape >= AK_EMITTER_SHAPE_COUNT) return AK_ERR_BAD_ARG;
    if (!finite3(e->center) || !finite3(e->direction) || !finite3(e->half_extents) ||
        !finite3(e->base_velocity) || !finite4(e->colour))
        return AK_ERR_BAD_DATA;
    const float vals[] = {e->radius,   e->speed_min, e->speed_max, e->lifetime_min, e->lifetime_max,
                          e->size_min, e->size_max,  e->mass,      e->cone_angle};
    for (size_t k = 0; k < sizeof vals / sizeof vals[0]; ++k)
        if (!ak_finitef(vals[k]) || vals[k] < 0.0f) return AK_ERR_BAD_ARG;
    if (e->half_extents.x < 0.0f || e->half_extents.y < 0.0f || e->half_extents.z < 0.0f)
        return AK_ERR_BAD_ARG;
    if (e->cone_angle > AK_PI + 1e-6f) return AK_ERR_BAD_ARG;
    if (e->shape == AK_EMITTER_MESH) {
        const size_t tris = e->mesh_indices.count / 3;
        if (!e->mesh_positions.ptr || !e->mesh_indices.ptr) return AK_ERR_NULL_ARG;
        if (tris == 0) return AK_ERR_EMPTY;
        if (e->mesh_indices.count % 3) return AK_ERR_BAD_ARG;
        if (!e->mesh_area_cdf.ptr || e->mesh_area_cdf.count < tris) return AK_ERR_SPAN_SMALL;
        for (size_t k = 0; k < e->mesh_indices.count; ++k)
            if (e->mesh_indices.ptr[k] >= e->mesh_positions.count) return AK_ERR_BAD_INDEX;
    }
    return AK_OK;
}

static ak_vec3 tri_corner(const ak_particle_emitter* e, size_t t, int c) {
    return e->mesh_positions.ptr[e->mesh_indices.ptr[3 * t + (size_t)c]];
}

/* Cumulative triangle areas, normalised to end at 1. AK_ERR_EMPTY for zero or non-finite area. */
static ak_result mesh_cdf(const ak_particle_emitter* e) {
    const size_t tris = e->mesh_indices.count / 3;
    double total = 0.0;
    for (size_t t = 0; t < tris; ++t) {
        ak_vec3 a = tri_corner(e, t, 0), b = tri_corner(e, t, 1), c = tri_corner(e, t, 2);
        total += 0.5 * (double)ak_vec3_length(ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(c, a)));
        e->mesh_area_cdf.ptr[t] = (float)total;
    }
    if (!(total > 0.0) || !isfinite(total)) return AK_ERR_EMPTY;
    const float inv = (float)(1.0 / total);
    for (size_t t = 0; t < tris; ++t) e->mesh_area_cdf.ptr[t] *= inv;
    e->mesh_area_cdf.ptr[tris - 1] = 1.0f;
    return AK_OK;
}

static ak_vec3 unit_sphere_sample(ak_rng* rng) {
    float z = 1.0f - 2.0f * ak_rng_float(rng), phi = 2.0f * AK_PI * ak_rng_float(rng);
    float s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return ak_vec3_make(s * cosf(phi), s * sinf(phi), z);
}

static void emit_one(ak_particles* ps, const ak_particle_emitter* e, ak_vec3 axis) {
    ak_rng* rng = &ps->rng;
    ak_vec3 p = e->center;
    switch (e->shape) {
    case AK_EMITTER_SPHERE:
        p = ak_vec3_madd(e->center, unit_sphere_sample(rng), e->radius * cbrtf(ak_rng_float(rng)));
        break;
    case AK_EMITTER_SPHERE_SURFACE:
        p = ak_vec3_madd(e->center, unit_sphere_sample(rng), e->radius);
        break;
    case AK_EMITTER_DISC: {
        ak_vec3 t, b;
        basis(axis, &t, &b);
        float r = e->radius * sqrtf(ak_rng_float(rng)), phi = 2.0f * AK_PI * ak_rng_float(rng);
        p = ak_vec3_madd(ak_vec3_madd(e->center, t, r * cosf(phi)), b, r * sinf(phi));
        break;
    }
    case AK_EMITTER_BOX:
        p = ak_vec3_make(e->center.x + e->half_extents.x * (2.0f * ak_rng_float(rng) - 1.0f),
                         e->center.y + e->half_extents.y * (2.0f * ak_rng_float(rng) - 1.0f),
                         e->center.z + e->half_extents.z * (2.0f * ak_rng_float(rng) - 1.0f));
        break;
    case AK_EMITTER_MESH: {
        const size_t tris = e->mesh_indices.count / 3;
        const float u = ak_rng_float(rng);
        size_t lo = 0, hi = tris - 1; /* first t with cdf[t] > u */
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (e->mesh_area_cdf.ptr[mid] > u)
                hi = mid;
            else
                lo = mid + 1;
        }
        ak_vec3 a = tri_corner(e, lo, 0), b = tri_corner(e, lo, 1), c = tri_corner(e, lo, 2);
        float s = sqrtf(ak_rng_float(rng)), w = ak_rng_float(rng);
        p = ak_vec3_add(ak_vec3_add(ak_vec3_scale(a, 1.0f - s), ak_vec3_scale(b, s * (1.0f - w))),
                        ak_vec3_scale(c, s * w));
        const ak_vec3 n = unit_or_up(ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(c, a)));
        p = ak_vec3_madd(
            p, n, PS_EMIT_OFFSET); /* off the surface, so a collider of the same mesh lets it go */
        if (!e->use_direction_on_mesh) axis = n;
        break;
    }
    default:
        break;
    }
    /* Direction uniform over the cone's solid angle. */
    ak_vec3 t, b;
    basis(axis, &t, &b);
    float cz = 1.0f - ak_rng_float(rng) * (1.0f - cosf(e->cone_angle));
    float sz = sqrtf(fmaxf(0.0f, 1.0f - cz * cz)), phi = 2.0f * AK_PI * ak_rng_float(rng);
    ak_vec3 dir =
        ak_vec3_add(ak_vec3_scale(axis, cz), ak_vec3_add(ak_vec3_scale(t, sz * cosf(phi)),
                                                         ak_vec3_scale(b, sz * sinf(phi))));
    float smax = e->speed_max > e->speed_min ? e->speed_max : e->speed_min;
    float speed = ak_rng_range(rng, e->speed_min, smax);
    float lmax = e->lifetime_max > e->lifetime_min ? e->lifetime_max : e->lifetime_min;
    float life = lmax > 0.0f ? ak_rng_range(rng, e->lifetime_min, lmax) : INFINITY;
    if (!(life > 0.0f)) life = lmax;
    float size_min = e->size_min > 0.0f ? e->size_min : 0.05f;
    float size_max = e->size_max > size_min ? e->size_max : size_min;
    float size = ak_rng_range(rng, size_min, size_max);
    float mass = e->mass > 0.0f ? e->mass : 1.0f;
    push(ps, p, ak_vec3_madd(e->base_velocity, dir, speed), 1.0f / mass, life, size,
         colour_or_white(e->colour));
}

static ak_result emit_count(ak_particles* ps, const ak_particle_emitter* e, uint64_t n,
                            uint32_t* out_emitted) {
    if (e->shape == AK_EMITTER_MESH && n > 0) {
        ak_result r = mesh_cdf(e);
        if (r != AK_OK) return r;
    }
    const ak_vec3 axis = unit_or_up(e->direction);
    uint32_t done = 0;
    for (uint64_t k = 0; k < n && ps->count < ps->capacity; ++k, ++done) emit_one(ps, e, axis);
    if (out_emitted) *out_emitted = done;
    return AK_OK;
}

ak_result ak_particles_emit(ak_particles* ps, ak_particle_emitter* e, float dt,
                            uint32_t* out_emitted) {
    if (out_emitted) *out_emitted = 0;
    if (!ps || !e) return AK_ERR_NULL_ARG;
    if (!(dt >= 0.0f) || !ak_finitef(dt) || !(e->rate >= 0.0f) || !ak_finitef(e->rate) ||
        !(e->carry >= 0.0) || !isfinite(e->carry))
        return AK_ERR_BAD_ARG;
    ak_result r = emitter_check(e);
    if (r != AK_OK) return r;
    double want = e->carry + (double)e->rate * (double)dt;
    double n = floor(want + 1e-4);
    if (n > (double)UINT32_MAX) n = (double)UINT32_MAX;
    r = emit_count(ps, e, (uint64_t)n, out_emitted);
    if (r != AK_OK) return r;
    e->carry = want - n > 0.0 ? want - n : 0.0;
    return AK_OK;
}

ak_result ak_particles_burst(ak_particles* ps, const ak_particle_emitter* e, uint32_t count,
                             uint32_t* out_emitted) {
    if (out_emitted) *out_emitted = 0;
    if (!ps || !e) return AK_ERR_NULL_ARG;
    ak_result r = emitter_check(e);
    if (r != AK_OK) return r;
    return emit_count(ps, e, count, out_emitted);
}

/* ---- collision meshes --------------------------------------------------------------- */

static ak_result mesh_rebuild(ak_particle_mesh* m) {
    float reach = 0.0f, speed = 0.0f;
    for (size_t t = 0; t < m->tri_count; ++t) {
        ak_vec3 a = m->verts[m->indices[3 * t]], b = m->verts[m->indices[3 * t + 1]],
                c = m->verts[m->indices[3 * t + 2]];
        ak_vec3 g = ak_vec3_scale(ak_vec3_add(ak_vec3_add(a, b), c), 1.0f / 3.0f);
        m->centroid[t] = g;
        ak_vec3 tv = ak_vec3_scale(
            ak_vec3_add(ak_vec3_add(m->vel[m->indices[3 * t]], m->vel[m->indices[3 * t + 1]]),
                        m->vel[m->indices[3 * t + 2]]),
            1.0f / 3.0f);
        m->tri_vel[t] = tv;
        speed = fmaxf(speed, ak_vec3_length(tv));
        reach = fmaxf(reach, fmaxf(ak_vec3_distance(a, g),
                                   fmaxf(ak_vec3_distance(b, g), ak_vec3_distance(c, g))));
    }
    /* A little over the exact reach so rounding cannot drop a triangle from a query. */
    m->reach = reach * 1.0001f + 1e-6f;
    m->max_speed = speed * 1.0001f;
    ak_grid_desc gd = {.cell_size = m->reach > 1e-6f ? 2.0f * m->reach : 1e-3f};
    return ak_grid_build(&gd, (ak_vec3_cspan){m->centroid, m->tri_count},
                         (ak_u8_span){m->grid_mem, m->grid_mem_size}, &m->grid);
}

ak_result ak_particle_mesh_create(const ak_particle_mesh_desc* desc, const ak_allocator* alloc,
                                  ak_particle_mesh** out_mesh) {
    if (out_mesh) *out_mesh = NULL;
    if (!desc || !out_mesh || !desc->positions.ptr || !desc->indices.ptr) return AK_ERR_NULL_ARG;
    const size_t tris = desc->indices.count / 3;
    if (tris == 0) return AK_ERR_EMPTY;
    if (desc->indices.count % 3 || tris >= (1u << 30) ||
        !(desc->restitution >= 0.0f && desc->restitution <= 1.0f) || !(desc->friction >= 0.0f) ||
        !ak_finitef(desc->friction))
        return AK_ERR_BAD_ARG;
    for (size_t k = 0; k < desc->indices.count; ++k)
        if (desc->indices.ptr[k] >= desc->positions.count) return AK_ERR_BAD_INDEX;
    for (size_t k = 0; k < desc->positions.count; ++k)
        if (!finite3(desc->positions.ptr[k])) return AK_ERR_BAD_DATA;
    ak_grid_desc gd = {.cell_size = 1.0f};
    const size_t gsize = ak_grid_memory_size(tris, &gd);
    const size_t nv = desc->positions.count;
    size_t off = akp_align16(sizeof(ak_particle_mesh));
    const size_t o_idx = off;
    off += akp_align16(desc->indices.count * sizeof(uint32_t));
    const size_t o_v = off;
    off += akp_align16(nv * sizeof(ak_vec3));
    const size_t o_vel = off;
    off += akp_align16(nv * sizeof(ak_vec3));
    const size_t o_tv = off;
    off += akp_align16(tris * sizeof(ak_vec3));
    const size_t o_c = off;
    off += akp_align16(tris * sizeof(ak_vec3));
    const size_t o_g = off;
    off += gsize;
    uint8_t* mem = (uint8_t*)akp_calloc(alloc, off);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_particle_mesh* m = (ak_particle_mesh*)(void*)mem;
    if (alloc) m->alloc = *alloc, m->has_alloc = true;
    m->vertex_count = nv;
    m->tri_count = tris;
    m->indices = (uint32_t*)(void*)(mem + o_idx);
    m->verts = (ak_vec3*)(void*)(mem + o_v);
    m->centroid = (ak_vec3*)(void*)(mem + o_c);
    m->vel = (ak_vec3*)(void*)(mem + o_vel);
    m->tri_vel = (ak_vec3*)(void*)(mem + o_tv);
    m->grid_mem = mem + o_g;
    m->grid_mem_size = gsize;
    m->restitution = desc->restitution;
    m->friction = desc->friction;
    memcpy(m->indices, desc->indices.ptr, desc->indices.count * sizeof(uint32_t));
    memcpy(m->verts, desc->positions.ptr, nv * sizeof(ak_vec3));
    ak_result r = mesh_rebuild(m);
    if (r != AK_OK) {
        ak_particle_mesh_destroy(m);
        return r;
    }
    *out_mesh = m;
    return AK_OK;
}

ak_result ak_particle_mesh_update(ak_particle_mesh* m, ak_vec3_cspan positions, float elapsed) {
    if (!m || !positions.ptr) return AK_ERR_NULL_ARG;
    if (positions.count < m->vertex_count) return AK_ERR_SPAN_SMALL;
    if (!(elapsed >= 0.0f) || !ak_finitef(elapsed)) return AK_ERR_BAD_ARG;
    for (size_t k = 0; k < m->vertex_count; ++k)
        if (!finite3(positions.ptr[k])) return AK_ERR_BAD_DATA;
    for (size_t k = 0; k < m->vertex_count; ++k) {
        ak_vec3 v = elapsed > 0.0f
                        ? ak_vec3_scale(ak_vec3_sub(positions.ptr[k], m->verts[k]), 1.0f / elapsed)
                        : ak_vec3_zero();
        m->vel[k] = finite3(v) ? v : ak_vec3_zero();
    }
    memcpy(m->verts, positions.ptr, m->vertex_count * sizeof(ak_vec3));
    return mesh_rebuild(m);
}

void ak_particle_mesh_destroy(ak_particle_mesh* m) {
    if (!m) return;
    ak_allocator a = m->alloc;
    akp_free(m->has_alloc ? &a : NULL, m);
}

/* ---- forces ------------------------------------------------------------------------- */

#define PS_CACHE 8 /* planes and vortices normalised once per step (more: on the fly) */

typedef struct step_ctx {
    ak_particles* ps;
    const ak_particles_world* w;
    float dt;
    bool pair_forces; /* force[] holds springs, LJ or callback forces */
    bool avx2;        /* this CPU runs the eight-wide fused block */
    ak_vec3 plane_n[PS_CACHE];
    ak_vec3 vortex_axis[PS_CACHE];
    ak_grid lj_grid;
    bool lj_grid_of_x0; /* lj_grid holds the step's start (built by the budget check) */
    float lj_cutoff;
    /* the state the current evaluation reads, and where accelerations go */
    const ak_vec3* X;
    const ak_vec3* V;
    ak_vec3* A;
} step_ctx;

static inline ak_vec3 plane_normal(const step_ctx* c, size_t k) {
    return k < PS_CACHE ? c->plane_n[k] : unit_or_up(c->w->planes.ptr[k].normal);
}

/* Acceleration of particle i at state (x, v) from gravity, drag, attractors, vortices and
 * the precomputed pair forces; 0 for pinned particles. */
static inline ak_vec3 accel_one(const step_ctx* c, size_t i, ak_vec3 x, ak_vec3 v) {
    const ak_particles_world* w = c->w;
    const float im = c->ps->inv_mass[i];
    if (im == 0.0f) return ak_vec3_zero();
    ak_vec3 f = c->pair_forces ? c->ps->force[i] : ak_vec3_zero();
    if (w->drag_linear != 0.0f || w->drag_quadratic != 0.0f) {
        ak_vec3 rel = ak_vec3_sub(v, w->wind);
        float k = w->drag_linear + w->drag_quadratic * ak_vec3_length(rel);
        f = ak_vec3_madd(f, rel, -k);
    }
    for (size_t k = 0; k < w->attractors.count; ++k) {
        const ak_particle_attractor* a = &w->attractors.ptr[k];
        ak_vec3 d = ak_vec3_sub(a->position, x);
        float r2 = ak_vec3_length_sq(d) + a->softening * a->softening;
        if (r2 > 0.0f) f = ak_vec3_madd(f, d, a->strength / (r2 * sqrtf(r2)));
    }
    for (size_t k = 0; k < w->vortices.count; ++k) {
        const ak_particle_vortex* vo = &w->vortices.ptr[k];
        ak_vec3 axis = k < PS_CACHE ? c->vortex_axis[k] : unit_or_up(vo->axis);
        ak_vec3 d = ak_vec3_sub(x, vo->center);
        ak_vec3 r = ak_vec3_madd(d, axis, -ak_vec3_dot(d, axis));
        float r2 = ak_vec3_length_sq(r) + vo->softening * vo->softening;
        if (r2 > 0.0f) f = ak_vec3_madd(f, ak_vec3_cross(axis, r), vo->strength / r2);
    }
    return ak_vec3_madd(w->gravity, f, im);
}

static bool lj_range(void* arg, size_t begin, size_t end) {
    step_ctx* c = (step_ctx*)arg;
    const ak_grid* g = &c->lj_grid;
    const ak_particle_lennard_jones* lj = &c->w->lennard_jones;
    const float cut2 = c->lj_cutoff * c->lj_cutoff, s2 = lj->sigma * lj->sigma;
    for (size_t i = begin; i < end; ++i) {
        const ak_vec3 p = c->X[i];
        const ak_grid_cell cc = ak_grid_cell_of(g, p);
        ak_vec3 f = ak_vec3_zero();
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    ak_grid_cell n = {cc.x + dx, cc.y + dy, cc.z + dz};
                    uint32_t m = ak_grid_cell_find(g, n);
                    if (m == UINT32_MAX) continue;
                    for (uint32_t k = g->cell_start[m]; k < g->cell_start[m + 1]; ++k) {
                        float ex = p.x - g->x[k], ey = p.y - g->y[k], ez = p.z - g->z[k];
                        float r2 = ex * ex + ey * ey + ez * ez;
                        if (!(r2 < cut2) || r2 == 0.0f) continue;
                        float q2 = s2 / r2, q6 = q2 * q2 * q2;
                        float s = 24.0f * lj->epsilon * (2.0f * q6 * q6 - q6) / r2;
                        f = ak_vec3_add(f, ak_vec3_make(ex * s, ey * s, ez * s));
                    }
                }
        c->ps->force[i] = ak_vec3_add(c->ps->force[i], f);
    }
    return false;
}

static bool accel_range(void* arg, size_t begin, size_t end) {
    step_ctx* c = (step_ctx*)arg;
    for (size_t i = begin; i < end; ++i) c->A[i] = accel_one(c, i, c->X[i], c->V[i]);
    return false;
}

/* Accelerations of every particle at state (X, V) and time t into A. */
static void eval_accel(step_ctx* c, const ak_vec3* X, const ak_vec3* V, ak_vec3* A, double t) {
    ak_particles* ps = c->ps;
    const ak_particles_world* w = c->w;
    const size_t n = ps->count;
    c->X = X, c->V = V, c->A = A;
    if (c->pair_forces) {
        memset(ps->force, 0, n * sizeof(ak_vec3));
        for (size_t k = 0; k < w->springs.count; ++k) {
            const ak_particle_spring* s = &w->springs.ptr[k];
            ak_vec3 d = ak_vec3_sub(X[s->j], X[s->i]);
            float len = ak_vec3_length(d);
            if (!(len > 0.0f)) continue;
            ak_vec3 u = ak_vec3_scale(d, 1.0f / len);
            float mag =
                s->k * (len - s->rest) + s->damping * ak_vec3_dot(ak_vec3_sub(V[s->j], V[s->i]), u);
            ps->force[s->i] = ak_vec3_madd(ps->force[s->i], u, mag);
            ps->force[s->j] = ak_vec3_madd(ps->force[s->j], u, -mag);
        }
        if (w->lennard_jones.epsilon != 0.0f && n > 1) {
            /* the budget check already sorted the step's start (x0 is a copy of it) */
            ak_grid_desc gd = {.cell_size = c->lj_cutoff};
            c->lj_grid_of_x0 = c->lj_grid_of_x0 && X == ps->x0;
            if (c->lj_grid_of_x0 || ak_grid_build(&gd, (ak_vec3_cspan){X, n},
                                                  (ak_u8_span){ps->grid_mem, ps->grid_mem_size}, &c->lj_grid) == AK_OK)
                parallel_for(ps->thread_count, n, lj_range, c);
        }
        if (w->callback) w->callback(X, V, ps->inv_mass, n, t, ps->force, w->callback_user);
    }
    parallel_for(ps->thread_count, n, accel_range, c);
}

/* ---- collisions --------------------------------------------------------------------- */

typedef struct contact {
    float tau;     /* fraction of the segment */
    ak_vec3 n;     /* unit normal, pointing to free space */
    ak_vec3 point; /* on the surface */
    float restitution, friction;
    bool is_mesh;
    ak_vec3 surface_velocity; /* of a moving mesh triangle; zero otherwise */
} contact;

/* Earliest contact of the segment x0 -> x1 with the colliders, skipping the collider `skip`
 * (index over planes, spheres, boxes, meshes in that order). */
static bool first_contact(const step_ctx* c, ak_vec3 x0, ak_vec3 x1, float h, size_t skip,
                          contact* out, size_t* out_which) {
    const ak_particles_world* w = c->w;
    bool hit = false;
    float best = 2.0f;
    size_t which = 0;
    const ak_vec3 d = ak_vec3_sub(x1, x0);
    for (size_t k = 0; k < w->planes.count; ++k, ++which) {
        if (which == skip) continue;
        const ak_particle_plane* pl = &w->planes.ptr[k];
        const ak_vec3 n = plane_normal(c, k);
        float s0 = ak_vec3_dot(n, x0) - pl->d, s1 = ak_vec3_dot(n, x1) - pl->d;
        if (s1 >= 0.0f) continue;
        float tau = s0 > 0.0f ? s0 / (s0 - s1) : 0.0f;
        if (tau < best) {
            best = tau, hit = true, *out_which = which;
            ak_vec3 p = s0 > 0.0f ? ak_vec3_madd(x0, d, tau) : x0;
            p = ak_vec3_madd(p, n, -(ak_vec3_dot(n, p) - pl->d)); /* exactly on the plane */
            *out = (contact){tau, n, p, pl->restitution, pl->friction, false, {0, 0, 0}};
        }
    }
    for (size_t k = 0; k < w->spheres.count; ++k, ++which) {
        if (which == skip) continue;
        const ak_particle_sphere* sp = &w->spheres.ptr[k];
        ak_vec3 m = ak_vec3_sub(x0, sp->center);
        float r2 = sp->radius * sp->radius, cc = ak_vec3_length_sq(m) - r2;
        float tau;
        ak_vec3 n;
        if (cc < 0.0f) { /* starts inside: push out from the centre */
            tau = 0.0f;
            n = ak_vec3_normalize(m);
            if (ak_vec3_length_sq(n) == 0.0f) n = ak_vec3_make(0, 1, 0);
        } else {
            float a = ak_vec3_length_sq(d), b = ak_vec3_dot(m, d);
            if (!(a > 0.0f) || b >= 0.0f) continue; /* not moving towards the centre */
            float disc = b * b - a * cc;
            if (disc < 0.0f) continue;
            tau = (-b - sqrtf(disc)) / a;
            if (tau > 1.0f) continue;
            if (tau < 0.0f) tau = 0.0f;
            n = ak_vec3_normalize(ak_vec3_madd(m, d, tau));
        }
        if (tau < best) {
            best = tau, hit = true, *out_which = which;
            *out = (contact){tau,
                             n,
                             ak_vec3_madd(sp->center, n, sp->radius),
                             sp->restitution,
                             sp->friction,
                             false,
                             {0, 0, 0}};
        }
    }
    for (size_t k = 0; k < w->boxes.count; ++k, ++which) {
        if (which == skip) continue;
        const ak_particle_box* bx = &w->boxes.ptr[k];
        const float lo[3] = {bx->min.x, bx->min.y, bx->min.z},
                    hi[3] = {bx->max.x, bx->max.y, bx->max.z};
        const float p0[3] = {x0.x, x0.y, x0.z}, dd[3] = {d.x, d.y, d.z};
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside = inside && p0[a] > lo[a] && p0[a] < hi[a];
        float tau = 0.0f;
        int axis = 0;
        float sign = 1.0f;
        if (inside) { /* push out through the nearest face */
            float best_pen = INFINITY;
            for (int a = 0; a < 3; ++a) {
                if (p0[a] - lo[a] < best_pen) best_pen = p0[a] - lo[a], axis = a, sign = -1.0f;
                if (hi[a] - p0[a] < best_pen) best_pen = hi[a] - p0[a], axis = a, sign = 1.0f;
            }
        } else {
            float t0 = 0.0f, t1 = 1.0f;
            bool miss = false;
            axis = -1;
            for (int a = 0; a < 3 && !miss; ++a) {
                if (dd[a] == 0.0f) {
                    miss = p0[a] <= lo[a] || p0[a] >= hi[a];
                    continue;
                }
                float ta = (lo[a] - p0[a]) / dd[a], tb = (hi[a] - p0[a]) / dd[a];
                float s = -1.0f;
                if (ta > tb) {
                    float tmp = ta;
                    ta = tb, tb = tmp, s = 1.0f;
                }
                if (ta > t0 || axis < 0) {
                    if (ta >= t0) t0 = ta, axis = a, sign = s;
                }
                if (tb < t1) t1 = tb;
                miss = t0 > t1;
            }
            if (miss || axis < 0 || t0 > 1.0f || t0 >= t1) continue;
            tau = t0;
        }
        if (tau < best) {
            float nv[3] = {0, 0, 0};
            nv[axis] = sign;
            ak_vec3 n = ak_vec3_make(nv[0], nv[1], nv[2]);
            ak_vec3 p = inside ? x0 : ak_vec3_madd(x0, d, tau);
            float pc[3] = {p.x, p.y, p.z};
            pc[axis] = sign > 0.0f ? hi[axis] : lo[axis];
            best = tau, hit = true, *out_which = which;
            *out = (contact){
                tau,   n,        ak_vec3_make(pc[0], pc[1], pc[2]), bx->restitution, bx->friction,
                false, {0, 0, 0}};
        }
    }
    for (size_t k = 0; k < w->meshes.count; ++k, ++which) {
        if (which == skip) continue;
        const ak_particle_mesh* m = w->meshes.ptr[k];
        const ak_grid* g = &m->grid;
        /* Cells whose triangles' centroids lie within reach (plus the triangles' motion over
         * the step) of the segment's box. */
        const float grow = m->reach + m->max_speed * h;
        ak_vec3 bmin = ak_vec3_make(fminf(x0.x, x1.x) - grow, fminf(x0.y, x1.y) - grow,
                                    fminf(x0.z, x1.z) - grow);
        ak_vec3 bmax = ak_vec3_make(fmaxf(x0.x, x1.x) + grow, fmaxf(x0.y, x1.y) + grow,
                                    fmaxf(x0.z, x1.z) + grow);
        ak_grid_cell c0 = ak_grid_cell_of(g, bmin), c1 = ak_grid_cell_of(g, bmax);
        const double span =
            ((double)c1.x - c0.x + 1) * ((double)c1.y - c0.y + 1) * ((double)c1.z - c0.z + 1);
        const bool scan = span > (double)g->cell_count;
        const int64_t total = scan ? (int64_t)g->cell_count : (int64_t)span;
        for (int64_t q = 0; q < total; ++q) {
            uint32_t cell;
            if (scan) {
                cell = (uint32_t)q;
            } else {
                int64_t nx = c1.x - c0.x + 1, ny = c1.y - c0.y + 1;
                ak_grid_cell cc = {(int32_t)(c0.x + q % nx), (int32_t)(c0.y + (q / nx) % ny),
                                   (int32_t)(c0.z + q / (nx * ny))};
                cell = ak_grid_cell_find(g, cc);
                if (cell == UINT32_MAX) continue;
            }
            for (uint32_t e = g->cell_start[cell]; e < g->cell_start[cell + 1]; ++e) {
                const uint32_t t = g->order[e];
                /* In the frame of the triangle (which moves by D = velocity * h and ends at
                 * its current pose) the particle goes from x0 + D to x1. */
                const ak_vec3 sv = m->tri_vel[t];
                const ak_vec3 r0 = ak_vec3_madd(x0, sv, h), dr = ak_vec3_sub(x1, r0);
                ak_vec3 a = m->verts[m->indices[3 * t]], b = m->verts[m->indices[3 * t + 1]],
                        cv = m->verts[m->indices[3 * t + 2]];
                /* Moller-Trumbore, two-sided */
                ak_vec3 e1 = ak_vec3_sub(b, a), e2 = ak_vec3_sub(cv, a);
                ak_vec3 pv = ak_vec3_cross(dr, e2);
                float det = ak_vec3_dot(e1, pv);
                if (fabsf(det) < 1e-20f) continue;
                float inv = 1.0f / det;
                ak_vec3 tv = ak_vec3_sub(r0, a);
                float u = ak_vec3_dot(tv, pv) * inv;
                if (u < 0.0f || u > 1.0f) continue;
                ak_vec3 qv = ak_vec3_cross(tv, e1);
                float v = ak_vec3_dot(dr, qv) * inv;
                if (v < 0.0f || u + v > 1.0f) continue;
                float tau = ak_vec3_dot(e2, qv) * inv;
                if (tau < 0.0f || tau > 1.0f || tau >= best) continue;
                ak_vec3 n = ak_vec3_normalize(ak_vec3_cross(e1, e2));
                if (ak_vec3_dot(n, dr) > 0.0f) n = ak_vec3_neg(n); /* face the side we come from */
                best = tau, hit = true, *out_which = which;
                /* The contact point where the triangle is at time tau of the step. */
                ak_vec3 p = ak_vec3_madd(ak_vec3_madd(r0, dr, tau), sv, -(1.0f - tau) * h);
                *out = (contact){tau, n, p, m->restitution, m->friction, true, sv};
            }
        }
    }
    return hit;
}

/* Moves the particle from (x0, v0) over time h to the integrator's (x1, v1), resolving
 * contacts on the way: at a contact the normal velocity reflects with restitution, the rest
 * of the step continues with the step's mean acceleration, penetration at the end is
 * projected out (that normal velocity change also counts as impulse), and Coulomb friction
 * takes at most friction times the normal impulse from the tangential velocity. */
static void collide_one(const step_ctx* c, ak_vec3 x0, ak_vec3 v0, ak_vec3* x1, ak_vec3* v1,
                        float h) {
    size_t skip = SIZE_MAX;
    for (int iter = 0; iter < PS_CONTACT_ITERATIONS; ++iter) {
        contact ct = {0};
        size_t which = 0;
        if (!first_contact(c, x0, *x1, h, skip, &ct, &which)) return;
        const ak_vec3 sv = ct.surface_velocity;
        const ak_vec3 acc = ak_vec3_scale(ak_vec3_sub(*v1, v0), 1.0f / h);
        ak_vec3 vc = ak_vec3_add(v0, ak_vec3_scale(ak_vec3_sub(*v1, v0), ct.tau));
        float vn = ak_vec3_dot(ak_vec3_sub(vc, sv), ct.n), jn = 0.0f;
        if (vn < 0.0f) {
            jn = -(1.0f + ct.restitution) * vn;
            vc = ak_vec3_madd(vc, ct.n, jn);
        }
        const float rem = (1.0f - ct.tau) * h;
        ak_vec3 ve = ak_vec3_madd(vc, acc, rem);
        ak_vec3 xe = ak_vec3_madd(ct.point, ak_vec3_add(vc, ve), 0.5f * rem);
        const ak_vec3 surface = ak_vec3_madd(ct.point, sv, rem); /* the contact point at the end */
        float pen = ak_vec3_dot(ak_vec3_sub(xe, surface), ct.n);
        if (pen < 0.0f) {
            xe = ak_vec3_madd(xe, ct.n, -pen);
            float ven = ak_vec3_dot(ak_vec3_sub(ve, sv), ct.n);
            if (ven < 0.0f) {
                ve = ak_vec3_madd(ve, ct.n, -ven);
                jn -= ven;
            }
        }
        if (ct.is_mesh) xe = ak_vec3_madd(xe, ct.n, PS_MESH_OFFSET);
        if (ct.friction > 0.0f && jn > 0.0f) {
            ak_vec3 rel = ak_vec3_sub(ve, sv);
            ak_vec3 vt = ak_vec3_madd(rel, ct.n, -ak_vec3_dot(rel, ct.n));
            float lt = ak_vec3_length(vt);
            if (lt > 0.0f) {
                float keep = fmaxf(0.0f, 1.0f - ct.friction * jn / lt);
                ve = ak_vec3_madd(ve, vt, keep - 1.0f);
            }
        }
        *x1 = xe;
        *v1 = ve;
        x0 = ct.point;
        v0 = vc;
        h = rem > 0.0f ? rem : h;
        skip = which;
    }
}

static inline bool any_colliders(const ak_particles_world* w) {
    return w->planes.count || w->spheres.count || w->boxes.count || w->meshes.count;
}

/* ---- integration passes ------------------------------------------------------------- */

/* A particle's new state is finite: the sum is NaN or inf when any component is. */
static inline bool state_finite(ak_vec3 x, ak_vec3 v) {
    const float sum = x.x + x.y + x.z + v.x + v.y + v.z;
    return sum - sum == 0.0f;
}

/* Symplectic Euler without pair forces, one particle: returns true when it is now dead. */
static inline bool fused_one(const step_ctx* c, size_t i, bool coll) {
    ak_particles* ps = c->ps;
    const float dt = c->dt;
    const float age = ps->age[i] + dt;
    ps->age[i] = age;
    bool dead = !(age < ps->life[i]);
    if (ps->inv_mass[i] == 0.0f) return dead;
    const ak_vec3 x0 = ps->pos[i], v0 = ps->vel[i];
    ak_vec3 v1 = ak_vec3_madd(v0, accel_one(c, i, x0, v0), dt);
    ak_vec3 x1 = ak_vec3_madd(x0, v1, dt);
    if (coll) collide_one(c, x0, v0, &x1, &v1, dt);
    ps->pos[i] = x1;
    ps->vel[i] = v1;
    return dead || !state_finite(x1, v1);
}

#if AK_SIMD_SSE2
/* Four particles at a time for worlds of gravity, drag, wind and at most PS_CACHE planes.
 * Every operation is the scalar path's, in the same order (no FMA), so a particle gets the
 * same bits whichever path (and so whichever thread split) handles it. Lanes whose new
 * position is behind a plane finish through the scalar collide_one. */
static bool simple_world(const ak_particles_world* w) {
    return w->attractors.count == 0 && w->vortices.count == 0 && w->spheres.count == 0 &&
           w->boxes.count == 0 && w->meshes.count == 0 && w->planes.count <= PS_CACHE;
}

/* Lanes l of a SIMD block at particle i with bit l set in hits went behind a plane: finish
 * them from their start-of-step state (x0, v0) through the scalar contact code. */
static void collide_lanes(const step_ctx* c, size_t i, int hits, const ak_vec3* x0, const ak_vec3* v0,
                          int lanes, bool* out_dead) {
    ak_particles* ps = c->ps;
    for (int l = 0; l < lanes; ++l) {
        if (!(hits & (1 << l))) continue;
        collide_one(c, x0[l], v0[l], &ps->pos[i + (size_t)l], &ps->vel[i + (size_t)l], c->dt);
        if (!state_finite(ps->pos[i + (size_t)l], ps->vel[i + (size_t)l])) *out_dead = true;
    }
}

static size_t fused_sse2(step_ctx* c, size_t begin, size_t end, bool* out_dead) {
    ak_particles* ps = c->ps;
    const ak_particles_world* w = c->w;
    const __m128 dt = _mm_set1_ps(c->dt), zero = _mm_setzero_ps();
    const __m128 gx = _mm_set1_ps(w->gravity.x), gy = _mm_set1_ps(w->gravity.y),
                 gz = _mm_set1_ps(w->gravity.z);
    const __m128 wx = _mm_set1_ps(w->wind.x), wy = _mm_set1_ps(w->wind.y),
                 wz = _mm_set1_ps(w->wind.z);
    const __m128 kl = _mm_set1_ps(w->drag_linear), kq = _mm_set1_ps(w->drag_quadratic);
    const __m128 sign = _mm_set1_ps(-0.0f);
    const bool drag = w->drag_linear != 0.0f || w->drag_quadratic != 0.0f;
    const size_t planes = w->planes.count;
    __m128 dead = zero;
    size_t i = begin;
    for (; i + 4 <= end; i += 4) {
        const __m128 age = _mm_add_ps(_mm_loadu_ps(ps->age + i), dt);
        _mm_storeu_ps(ps->age + i, age);
        dead = _mm_or_ps(dead, _mm_cmpnlt_ps(age, _mm_loadu_ps(ps->life + i)));
        const __m128 im = _mm_loadu_ps(ps->inv_mass + i);
        const __m128 moving = _mm_cmpneq_ps(im, zero);
        __m128 x, y, z, vx, vy, vz;
        akp_simd_load_vec3x4(&ps->pos[i].x, &x, &y, &z);
        akp_simd_load_vec3x4(&ps->vel[i].x, &vx, &vy, &vz);
        __m128 fx = zero, fy = zero, fz = zero;
        if (drag) {
            const __m128 rx = _mm_sub_ps(vx, wx), ry = _mm_sub_ps(vy, wy), rz = _mm_sub_ps(vz, wz);
            const __m128 len = _mm_sqrt_ps(
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(rx, rx), _mm_mul_ps(ry, ry)), _mm_mul_ps(rz, rz)));
            const __m128 nk = _mm_xor_ps(_mm_add_ps(kl, _mm_mul_ps(kq, len)), sign); /* -k */
            fx = _mm_add_ps(zero, _mm_mul_ps(rx, nk));
            fy = _mm_add_ps(zero, _mm_mul_ps(ry, nk));
            fz = _mm_add_ps(zero, _mm_mul_ps(rz, nk));
        }
        const __m128 ax = _mm_add_ps(gx, _mm_mul_ps(fx, im)),
                     ay = _mm_add_ps(gy, _mm_mul_ps(fy, im)),
                     az = _mm_add_ps(gz, _mm_mul_ps(fz, im));
        const __m128 nvx = akp_simd_select(moving, _mm_add_ps(vx, _mm_mul_ps(ax, dt)), vx);
        const __m128 nvy = akp_simd_select(moving, _mm_add_ps(vy, _mm_mul_ps(ay, dt)), vy);
        const __m128 nvz = akp_simd_select(moving, _mm_add_ps(vz, _mm_mul_ps(az, dt)), vz);
        const __m128 nx = akp_simd_select(moving, _mm_add_ps(x, _mm_mul_ps(nvx, dt)), x);
        const __m128 ny = akp_simd_select(moving, _mm_add_ps(y, _mm_mul_ps(nvy, dt)), y);
        const __m128 nz = akp_simd_select(moving, _mm_add_ps(z, _mm_mul_ps(nvz, dt)), z);
        __m128 behind = zero;
        for (size_t k = 0; k < planes; ++k) {
            const ak_vec3 n = c->plane_n[k];
            const __m128 s1 = _mm_sub_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(n.x), nx),
                                                               _mm_mul_ps(_mm_set1_ps(n.y), ny)),
                                                    _mm_mul_ps(_mm_set1_ps(n.z), nz)),
                                         _mm_set1_ps(w->planes.ptr[k].d));
            behind = _mm_or_ps(behind, _mm_cmplt_ps(s1, zero));
        }
        const __m128 sum =
            _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_add_ps(nx, ny), nz), nvx), nvy), nvz);
        dead = _mm_or_ps(dead, _mm_and_ps(moving, _mm_cmpneq_ps(_mm_sub_ps(sum, sum), zero)));
        int hits = _mm_movemask_ps(_mm_and_ps(behind, moving));
        if (hits) { /* keep the start of the step for the scalar contact code */
            ak_vec3 x0[4], v0[4];
            memcpy(x0, &ps->pos[i], sizeof x0);
            memcpy(v0, &ps->vel[i], sizeof v0);
            akp_simd_store_vec3x4(&ps->pos[i].x, nx, ny, nz);
            akp_simd_store_vec3x4(&ps->vel[i].x, nvx, nvy, nvz);
            collide_lanes(c, i, hits, x0, v0, 4, out_dead);
        } else {
            akp_simd_store_vec3x4(&ps->pos[i].x, nx, ny, nz);
            akp_simd_store_vec3x4(&ps->vel[i].x, nvx, nvy, nvz);
        }
    }
    if (_mm_movemask_ps(dead)) *out_dead = true;
    return i;
}

#if defined(__GNUC__) && defined(__x86_64__)
#define PS_HAVE_AVX2 1
#include <immintrin.h>
/* The same block eight particles wide (AVX2 without FMA: the same roundings as SSE2 and the
 * scalar path). Chosen at run time when the CPU has AVX2. */
__attribute__((target("avx2"))) static size_t fused_avx2(step_ctx* c, size_t begin, size_t end,
                                                         bool* out_dead) {
    ak_particles* ps = c->ps;
    const ak_particles_world* w = c->w;
    const __m256 dt = _mm256_set1_ps(c->dt), zero = _mm256_setzero_ps();
    const __m256 gx = _mm256_set1_ps(w->gravity.x), gy = _mm256_set1_ps(w->gravity.y),
                 gz = _mm256_set1_ps(w->gravity.z);
    const __m256 wx = _mm256_set1_ps(w->wind.x), wy = _mm256_set1_ps(w->wind.y),
                 wz = _mm256_set1_ps(w->wind.z);
    const __m256 kl = _mm256_set1_ps(w->drag_linear), kq = _mm256_set1_ps(w->drag_quadratic);
    const __m256 sign = _mm256_set1_ps(-0.0f);
    const bool drag = w->drag_linear != 0.0f || w->drag_quadratic != 0.0f;
    const size_t planes = w->planes.count;
    __m256 dead = zero;
    size_t i = begin;
    for (; i + 8 <= end; i += 8) {
        const __m256 age = _mm256_add_ps(_mm256_loadu_ps(ps->age + i), dt);
        _mm256_storeu_ps(ps->age + i, age);
        dead = _mm256_or_ps(dead, _mm256_cmp_ps(age, _mm256_loadu_ps(ps->life + i), _CMP_NLT_UQ));
        const __m256 im = _mm256_loadu_ps(ps->inv_mass + i);
        const __m256 moving = _mm256_cmp_ps(im, zero, _CMP_NEQ_UQ);
        __m128 x0, y0, z0, x1, y1, z1, vx0, vy0, vz0, vx1, vy1, vz1;
        akp_simd_load_vec3x4(&ps->pos[i].x, &x0, &y0, &z0);
        akp_simd_load_vec3x4(&ps->pos[i + 4].x, &x1, &y1, &z1);
        akp_simd_load_vec3x4(&ps->vel[i].x, &vx0, &vy0, &vz0);
        akp_simd_load_vec3x4(&ps->vel[i + 4].x, &vx1, &vy1, &vz1);
        const __m256 x = _mm256_set_m128(x1, x0), y = _mm256_set_m128(y1, y0),
                     z = _mm256_set_m128(z1, z0);
        const __m256 vx = _mm256_set_m128(vx1, vx0), vy = _mm256_set_m128(vy1, vy0),
                     vz = _mm256_set_m128(vz1, vz0);
        __m256 fx = zero, fy = zero, fz = zero;
        if (drag) {
            const __m256 rx = _mm256_sub_ps(vx, wx), ry = _mm256_sub_ps(vy, wy),
                         rz = _mm256_sub_ps(vz, wz);
            const __m256 len = _mm256_sqrt_ps(
                _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(rx, rx), _mm256_mul_ps(ry, ry)),
                              _mm256_mul_ps(rz, rz)));
            const __m256 nk = _mm256_xor_ps(_mm256_add_ps(kl, _mm256_mul_ps(kq, len)), sign);
            fx = _mm256_add_ps(zero, _mm256_mul_ps(rx, nk));
            fy = _mm256_add_ps(zero, _mm256_mul_ps(ry, nk));
            fz = _mm256_add_ps(zero, _mm256_mul_ps(rz, nk));
        }
        const __m256 ax = _mm256_add_ps(gx, _mm256_mul_ps(fx, im)),
                     ay = _mm256_add_ps(gy, _mm256_mul_ps(fy, im)),
                     az = _mm256_add_ps(gz, _mm256_mul_ps(fz, im));
        const __m256 nvx = _mm256_blendv_ps(vx, _mm256_add_ps(vx, _mm256_mul_ps(ax, dt)), moving);
        const __m256 nvy = _mm256_blendv_ps(vy, _mm256_add_ps(vy, _mm256_mul_ps(ay, dt)), moving);
        const __m256 nvz = _mm256_blendv_ps(vz, _mm256_add_ps(vz, _mm256_mul_ps(az, dt)), moving);
        const __m256 nx = _mm256_blendv_ps(x, _mm256_add_ps(x, _mm256_mul_ps(nvx, dt)), moving);
        const __m256 ny = _mm256_blendv_ps(y, _mm256_add_ps(y, _mm256_mul_ps(nvy, dt)), moving);
        const __m256 nz = _mm256_blendv_ps(z, _mm256_add_ps(z, _mm256_mul_ps(nvz, dt)), moving);
        __m256 behind = zero;
        for (size_t k = 0; k < planes; ++k) {
            const ak_vec3 n = c->plane_n[k];
            const __m256 s1 =
                _mm256_sub_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(n.x), nx),
                                                          _mm256_mul_ps(_mm256_set1_ps(n.y), ny)),
                                            _mm256_mul_ps(_mm256_set1_ps(n.z), nz)),
                              _mm256_set1_ps(w->planes.ptr[k].d));
            behind = _mm256_or_ps(behind, _mm256_cmp_ps(s1, zero, _CMP_LT_OQ));
        }
        const __m256 sum = _mm256_add_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(_mm256_add_ps(nx, ny), nz), nvx), nvy), nvz);
        dead = _mm256_or_ps(
            dead, _mm256_and_ps(moving, _mm256_cmp_ps(_mm256_sub_ps(sum, sum), zero, _CMP_NEQ_UQ)));
        const int hits = _mm256_movemask_ps(_mm256_and_ps(behind, moving));
        ak_vec3 xs0[8], vs0[8];
        if (hits) {
            memcpy(xs0, &ps->pos[i], sizeof xs0);
            memcpy(vs0, &ps->vel[i], sizeof vs0);
        }
        akp_simd_store_vec3x4(&ps->pos[i].x, _mm256_castps256_ps128(nx), _mm256_castps256_ps128(ny),
                              _mm256_castps256_ps128(nz));
        akp_simd_store_vec3x4(&ps->pos[i + 4].x, _mm256_extractf128_ps(nx, 1),
                              _mm256_extractf128_ps(ny, 1), _mm256_extractf128_ps(nz, 1));
        akp_simd_store_vec3x4(&ps->vel[i].x, _mm256_castps256_ps128(nvx),
                              _mm256_castps256_ps128(nvy), _mm256_castps256_ps128(nvz));
        akp_simd_store_vec3x4(&ps->vel[i + 4].x, _mm256_extractf128_ps(nvx, 1),
                              _mm256_extractf128_ps(nvy, 1), _mm256_extractf128_ps(nvz, 1));
        if (hits) collide_lanes(c, i, hits, xs0, vs0, 8, out_dead);
    }
    if (_mm256_movemask_ps(dead)) *out_dead = true;
    return i;
}
#else
#define PS_HAVE_AVX2 0
#endif
#endif

/* Symplectic Euler without pair forces: one fused pass (read and write each array once). */
static bool fused_symplectic(void* arg, size_t begin, size_t end) {
    step_ctx* c = (step_ctx*)arg;
    const bool coll = any_colliders(c->w);
    bool dead = false;
    size_t i = begin;
#if AK_SIMD_SSE2
    if (simple_world(c->w)) {
#if PS_HAVE_AVX2
        if (c->avx2) i = fused_avx2(c, begin, end, &dead);
#endif
        i = fused_sse2(c, i, end, &dead);
    }
#endif
    for (; i < end; ++i) dead |= fused_one(c, i, coll);
    return dead;
}

static bool save_state(void* arg, size_t begin, size_t end) {
    step_ctx* c = (step_ctx*)arg;
    ak_particles* ps = c->ps;
    memcpy(ps->x0 + begin, ps->pos + begin, (end - begin) * sizeof(ak_vec3));
    memcpy(ps->v0 + begin, ps->vel + begin, (end - begin) * sizeof(ak_vec3));
    return false;
}

/* One Euler step from (x0, v0) with acc: explicit Euler moves with the old velocity,
 * symplectic Euler with the new one. */
static void euler_range(const step_ctx* c, size_t begin, size_t end, bool symplectic) {
    ak_particles* ps = c->ps;
    for (size_t i = begin; i < end; ++i) {
        if (ps->inv_mass[i] == 0.0f) continue;
        const ak_vec3 v1 = ak_vec3_madd(ps->v0[i], ps->acc[i], c->dt);
        ps->pos[i] = ak_vec3_madd(ps->x0[i], symplectic ? v1 : ps->v0[i], c->dt);
        ps->vel[i] = v1;
    }
}

static bool pass_euler(void* arg, size_t begin, size_t end) {
    euler_range((const step_ctx*)arg, begin, end, false);
    return false;
}

static bool pass_symplectic(void* arg, size_t begin, size_t end) {
    euler_range((const step_ctx*)arg, begin, end, true);
    return false;
}

/* Verlet, first half: new positions and the predicted velocities (into vs). */
static bool pass_verlet_a(void* arg, size_t begin, size_t end) {
    step_ctx* c = (step_ctx*)arg;
    ak_particles* ps = c->ps;
    const float dt = c->dt;
    for (size_t i = begin; i < end; ++i) {
        if (ps->inv_mass[i] == 0.0f) {
            ps->xs[i] = ps->x0[i], ps->vs[i] = ps->v0[i];
            continue;
        }
        ps->xs[i] =
            ak_vec3_madd(ak_vec3_madd(ps->x0[i], ps->v0[i], dt), ps->acc[i], 0.5f * dt * dt);
        ps->vs[i] = ak_vec3_madd(ps->v0[i], ps->acc[i], dt);
    }
    return false;
}

/* Verlet, second half: acc holds a(t), sx holds a(t + dt). */
static bool pass_verlet_b(void* arg, size_t begin, size_t end) {
    step_ctx* c = (step_ctx*)arg;
    ak_particles* ps = c->ps;
    for (size_t i = begin; i < end; ++i) {
        if (ps->inv_mass[i] == 0.0f) continue;
        ps->pos[i] = ps->xs[i];
        ps->vel[i] = ak_vec3_madd(ps->v0[i], ak_vec3_add(ps->acc[i], ps->sx[i]), 0.5f * c->dt);
    }
    return false;
}

/* RK4 stage s (1..3): accumulate k_s (velocity = V stage, acceleration = acc) into the sums
 * with weight w, and build the next stage's state x0 + h k_s into xs/vs. */
typedef struct rk_ctx {
    step_ctx* c;
    float weight, h;
    bool first, last;
} rk_ctx;

static bool pass_rk(void* arg, size_t begin, size_t end) {
    rk_ctx* r = (rk_ctx*)arg;
    ak_particles* ps = r->c->ps;
    const float dt = r->c->dt;
    for (size_t i = begin; i < end; ++i) {
        const ak_vec3 kv = r->first ? ps->v0[i] : ps->vs[i]; /* dx/dt of this stage */
        const ak_vec3 ka = ps->acc[i];                       /* dv/dt of this stage */
        ak_vec3 sx = r->first ? ak_vec3_zero() : ps->sx[i],
                sv = r->first ? ak_vec3_zero() : ps->sv[i];
        sx = ak_vec3_madd(sx, kv, r->weight);
        sv = ak_vec3_madd(sv, ka, r->weight);
        if (r->last) {
            if (ps->inv_mass[i] == 0.0f) continue;
            ps->pos[i] = ak_vec3_madd(ps->x0[i], sx, dt / 6.0f);
            ps->vel[i] = ak_vec3_madd(ps->v0[i], sv, dt / 6.0f);
        } else {
            ps->sx[i] = sx, ps->sv[i] = sv;
            ps->xs[i] = ak_vec3_madd(ps->x0[i], kv, r->h);
            ps->vs[i] = ak_vec3_madd(ps->v0[i], ka, r->h);
        }
    }
    return false;
}

static bool pass_collide_age(void* arg, size_t begin, size_t end) {
    step_ctx* c = (step_ctx*)arg;
    ak_particles* ps = c->ps;
    const bool coll = any_colliders(c->w);
    bool dead = false;
    for (size_t i = begin; i < end; ++i) {
        ps->age[i] += c->dt;
        dead |= !(ps->age[i] < ps->life[i]);
        if (coll && ps->inv_mass[i] != 0.0f)
            collide_one(c, ps->x0[i], ps->v0[i], &ps->pos[i], &ps->vel[i], c->dt);
        dead |= !state_finite(ps->pos[i], ps->vel[i]);
    }
    return dead;
}

/* Stable removal of dead (age >= lifetime) and non-finite particles. */
static void compact(ak_particles* ps) {
    size_t out = 0;
    for (size_t i = 0; i < ps->count; ++i) {
        bool alive = ps->age[i] < ps->life[i] && finite3(ps->pos[i]) && finite3(ps->vel[i]);
        if (!alive) continue;
        if (out != i) {
            ps->pos[out] = ps->pos[i];
            ps->vel[out] = ps->vel[i];
            ps->force[out] = ps->force[i];
            ps->inv_mass[out] = ps->inv_mass[i];
            ps->age[out] = ps->age[i];
            ps->life[out] = ps->life[i];
            ps->size[out] = ps->size[i];
            ps->colour[out] = ps->colour[i];
            ps->id[out] = ps->id[i];
        }
        ++out;
    }
    ps->count = out;
}

/* ---- step --------------------------------------------------------------------------- */

#define PS_SPAN_OK(s) ((s).ptr != NULL || (s).count == 0)

static ak_result world_check(const ak_particles* ps, const ak_particles_world* w) {
    if (!PS_SPAN_OK(w->attractors) || !PS_SPAN_OK(w->vortices) || !PS_SPAN_OK(w->springs) ||
        !PS_SPAN_OK(w->planes) || !PS_SPAN_OK(w->spheres) || !PS_SPAN_OK(w->boxes) ||
        !PS_SPAN_OK(w->meshes))
        return AK_ERR_NULL_ARG;
    for (size_t k = 0; k < w->meshes.count; ++k)
        if (!w->meshes.ptr[k]) return AK_ERR_NULL_ARG;
    if (!finite3(w->gravity) || !finite3(w->wind) || !ak_finitef(w->drag_linear) ||
        !ak_finitef(w->drag_quadratic))
        return AK_ERR_BAD_DATA;
    if (w->drag_linear < 0.0f || w->drag_quadratic < 0.0f) return AK_ERR_BAD_ARG;
    for (size_t k = 0; k < w->attractors.count; ++k) {
        const ak_particle_attractor* a = &w->attractors.ptr[k];
        if (!finite3(a->position) || !ak_finitef(a->strength) || !ak_finitef(a->softening))
            return AK_ERR_BAD_DATA;
        if (a->softening < 0.0f) return AK_ERR_BAD_ARG;
    }
    for (size_t k = 0; k < w->vortices.count; ++k) {
        const ak_particle_vortex* v = &w->vortices.ptr[k];
        if (!finite3(v->center) || !finite3(v->axis) || !ak_finitef(v->strength) ||
            !ak_finitef(v->softening))
            return AK_ERR_BAD_DATA;
        if (v->softening < 0.0f) return AK_ERR_BAD_ARG;
    }
    for (size_t k = 0; k < w->springs.count; ++k) {
        const ak_particle_spring* s = &w->springs.ptr[k];
        if (!ak_finitef(s->rest) || !ak_finitef(s->k) || !ak_finitef(s->damping))
            return AK_ERR_BAD_DATA;
        if (s->rest < 0.0f || s->k < 0.0f || s->damping < 0.0f) return AK_ERR_BAD_ARG;
        if (s->i >= ps->count || s->j >= ps->count) return AK_ERR_BAD_INDEX;
    }
    const ak_particle_lennard_jones* lj = &w->lennard_jones;
    if (!ak_finitef(lj->epsilon) || !ak_finitef(lj->sigma) || !ak_finitef(lj->cutoff))
        return AK_ERR_BAD_DATA;
    if (lj->epsilon != 0.0f && (!(lj->sigma > 0.0f) || lj->cutoff < 0.0f)) return AK_ERR_BAD_ARG;
#define PS_RESPONSE_OK(o)                                                                          \
    ((o).restitution >= 0.0f && (o).restitution <= 1.0f && (o).friction >= 0.0f &&                 \
     ak_finitef((o).friction))
    for (size_t k = 0; k < w->planes.count; ++k) {
        const ak_particle_plane* p = &w->planes.ptr[k];
        if (!finite3(p->normal) || !ak_finitef(p->d)) return AK_ERR_BAD_DATA;
        if (!PS_RESPONSE_OK(*p)) return AK_ERR_BAD_ARG;
    }
    for (size_t k = 0; k < w->spheres.count; ++k) {
        const ak_particle_sphere* s = &w->spheres.ptr[k];
        if (!finite3(s->center) || !ak_finitef(s->radius)) return AK_ERR_BAD_DATA;
        if (!PS_RESPONSE_OK(*s) || s->radius < 0.0f) return AK_ERR_BAD_ARG;
    }
    for (size_t k = 0; k < w->boxes.count; ++k) {
        const ak_particle_box* b = &w->boxes.ptr[k];
        if (!finite3(b->min) || !finite3(b->max)) return AK_ERR_BAD_DATA;
        if (!PS_RESPONSE_OK(*b) || b->min.x > b->max.x || b->min.y > b->max.y ||
            b->min.z > b->max.z)
            return AK_ERR_BAD_ARG;
    }
#undef PS_RESPONSE_OK
    return AK_OK;
}

ak_result ak_particles_step(ak_particles* ps, const ak_particles_world* w, float dt) {
    if (!ps || !w) return AK_ERR_NULL_ARG;
    if (!(dt > 0.0f) || !ak_finitef(dt)) return AK_ERR_BAD_ARG;
    ak_result r = world_check(ps, w);
    if (r != AK_OK) return r;
    step_ctx c;
    memset(&c, 0, sizeof c);
    c.ps = ps;
    c.w = w;
    c.dt = dt;
    c.pair_forces = w->springs.count > 0 || w->lennard_jones.epsilon != 0.0f || w->callback != NULL;
#if AK_SIMD_SSE2 && PS_HAVE_AVX2
    c.avx2 = __builtin_cpu_supports("avx2");
#endif
    c.lj_cutoff =
        w->lennard_jones.cutoff > 0.0f ? w->lennard_jones.cutoff : 2.5f * w->lennard_jones.sigma;
    for (size_t k = 0; k < w->planes.count && k < PS_CACHE; ++k)
        c.plane_n[k] = unit_or_up(w->planes.ptr[k].normal);
    for (size_t k = 0; k < w->vortices.count && k < PS_CACHE; ++k)
        c.vortex_axis[k] = unit_or_up(w->vortices.ptr[k].axis);
    const size_t n = ps->count;
    const uint32_t th = ps->thread_count;
    const double t = ps->time;
    if (w->lennard_jones.epsilon != 0.0f && n > 1) { /* the work budget, before anything moves */
        ak_grid_desc gd = {.cell_size = c.lj_cutoff};
        const uint64_t budget = w->lennard_jones.max_pair_tests ? w->lennard_jones.max_pair_tests
                                                                : AK_PARTICLES_LJ_DEFAULT_PAIR_TESTS;
        c.lj_grid_of_x0 = ak_grid_build(&gd, (ak_vec3_cspan){ps->pos, n},
                                        (ak_u8_span){ps->grid_mem, ps->grid_mem_size}, &c.lj_grid) == AK_OK;
        if (c.lj_grid_of_x0 && ak_grid_candidate_count(&c.lj_grid, c.lj_cutoff) > budget) return AK_ERR_BUDGET;
    }

    bool dead;
    if (ps->integrator == AK_INTEGRATOR_SYMPLECTIC && !c.pair_forces) {
        dead = parallel_for(th, n, fused_symplectic, &c);
    } else {
        parallel_for(th, n, save_state, &c);
        switch (ps->integrator) {
        case AK_INTEGRATOR_EULER:
            eval_accel(&c, ps->x0, ps->v0, ps->acc, t);
            parallel_for(th, n, pass_euler, &c);
            break;
        case AK_INTEGRATOR_VERLET:
            eval_accel(&c, ps->x0, ps->v0, ps->acc, t);
            parallel_for(th, n, pass_verlet_a, &c);
            eval_accel(&c, ps->xs, ps->vs, ps->sx, t + dt);
            parallel_for(th, n, pass_verlet_b, &c);
            break;
        case AK_INTEGRATOR_RK4: {
            rk_ctx rk = {&c, 1.0f, 0.5f * dt, true, false};
            eval_accel(&c, ps->x0, ps->v0, ps->acc, t); /* k1 */
            parallel_for(th, n, pass_rk, &rk);
            eval_accel(&c, ps->xs, ps->vs, ps->acc, t + 0.5 * dt); /* k2 */
            rk = (rk_ctx){&c, 2.0f, 0.5f * dt, false, false};
            parallel_for(th, n, pass_rk, &rk);
            eval_accel(&c, ps->xs, ps->vs, ps->acc, t + 0.5 * dt); /* k3 */
            rk = (rk_ctx){&c, 2.0f, dt, false, false};
            parallel_for(th, n, pass_rk, &rk);
            eval_accel(&c, ps->xs, ps->vs, ps->acc, t + dt); /* k4 */
            rk = (rk_ctx){&c, 1.0f, dt, false, true};
            parallel_for(th, n, pass_rk, &rk);
            break;
        }
        default: /* SYMPLECTIC with pair forces */
            eval_accel(&c, ps->x0, ps->v0, ps->acc, t);
            parallel_for(th, n, pass_symplectic, &c);
            break;
        }
        dead = parallel_for(th, n, pass_collide_age, &c);
    }
    if (dead) compact(ps);
    ps->time += (double)dt;
    return AK_OK;
}

/* ---- appearance over life ----------------------------------------------------------------- */

static bool vec4_finite(ak_vec4 v) { return ak_finitef(v.x) && ak_finitef(v.y) && ak_finitef(v.z) && ak_finitef(v.w); }

static float life_fraction(float age, float lifetime) {
    if (!(lifetime > 0.0f) || !ak_finitef(lifetime) || !ak_finitef(age)) return 0.0f;
    float t = age / lifetime;
    return t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
}

/* Index k of the segment [keys[k], keys[k + 1]] holding t, and the weight of key k + 1, for a
 * key table of count >= 2 entries whose t values are at stride bytes. */
static size_t key_segment(const float* first_t, size_t stride, size_t count, float t, float* out_w) {
    size_t k = 0;
    const char* base = (const char*)first_t;
    while (k + 2 < count && t > *(const float*)(const void*)(base + (k + 1) * stride)) ++k;
    float t0 = *(const float*)(const void*)(base + k * stride);
    float t1 = *(const float*)(const void*)(base + (k + 1) * stride);
    float w = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0f;
    *out_w = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
    return k;
}

ak_result ak_particle_look_validate(const ak_particle_look* look) {
    if (!look) return AK_ERR_NULL_ARG;
    if (look->colour_key_count > AK_PARTICLE_LOOK_MAX_KEYS || look->size_key_count > AK_PARTICLE_LOOK_MAX_KEYS)
        return AK_ERR_BAD_ARG;
    if (!(look->frame_rate >= 0.0f) || !ak_finitef(look->frame_rate)) return AK_ERR_BAD_ARG;
    for (uint32_t k = 0; k < look->colour_key_count; ++k) {
        const ak_particle_colour_key* c = &look->colour_keys[k];
        if (!(c->t >= 0.0f && c->t <= 1.0f) || !vec4_finite(c->colour)) return AK_ERR_BAD_ARG;
        if (k && !(c->t > look->colour_keys[k - 1].t)) return AK_ERR_BAD_ARG;
    }
    for (uint32_t k = 0; k < look->size_key_count; ++k) {
        const ak_particle_size_key* c = &look->size_keys[k];
        if (!(c->t >= 0.0f && c->t <= 1.0f) || !(c->size >= 0.0f) || !ak_finitef(c->size)) return AK_ERR_BAD_ARG;
        if (k && !(c->t > look->size_keys[k - 1].t)) return AK_ERR_BAD_ARG;
    }
    return AK_OK;
}

ak_vec4 ak_particle_look_colour(const ak_particle_look* look, float age, float lifetime) {
    if (!look || look->colour_key_count == 0) return ak_vec4_make(1, 1, 1, 1);
    const uint32_t n = look->colour_key_count < AK_PARTICLE_LOOK_MAX_KEYS ? look->colour_key_count
                                                                         : AK_PARTICLE_LOOK_MAX_KEYS;
    const ak_particle_colour_key* k = look->colour_keys;
    const float t = life_fraction(age, lifetime);
    if (n == 1 || t <= k[0].t) return k[0].colour;
    if (t >= k[n - 1].t) return k[n - 1].colour;
    float w;
    size_t i = key_segment(&k[0].t, sizeof *k, n, t, &w);
    const ak_vec4 a = k[i].colour, b = k[i + 1].colour;
    return ak_vec4_make(a.x + (b.x - a.x) * w, a.y + (b.y - a.y) * w, a.z + (b.z - a.z) * w, a.w + (b.w - a.w) * w);
}

float ak_particle_look_size(const ak_particle_look* look, float age, float lifetime) {
    if (!look || look->size_key_count == 0) return 1.0f;
    const uint32_t n = look->size_key_count < AK_PARTICLE_LOOK_MAX_KEYS ? look->size_key_count
                                                                       : AK_PARTICLE_LOOK_MAX_KEYS;
    const ak_particle_size_key* k = look->size_keys;
    const float t = life_fraction(age, lifetime);
    if (n == 1 || t <= k[0].t) return k[0].size;
    if (t >= k[n - 1].t) return k[n - 1].size;
    float w;
    size_t i = key_segment(&k[0].t, sizeof *k, n, t, &w);
    return k[i].size + (k[i + 1].size - k[i].size) * w;
}

uint32_t ak_particle_look_frame(const ak_particle_look* look, float age, float lifetime) {
    if (!look || look->frame_count <= 1) return 0;
    const uint32_t n = look->frame_count;
    if (look->frame_rate > 0.0f && ak_finitef(look->frame_rate)) {
        double f = floor((double)(ak_finitef(age) && age > 0.0f ? age : 0.0f) * (double)look->frame_rate);
        return (uint32_t)fmod(f, (double)n);
    }
    float f = floorf(life_fraction(age, lifetime) * (float)n);
    return f >= (float)n ? n - 1 : (uint32_t)f;
}
