/* Particle liquids: MCG 2003 kernels, PBF (Macklin & Mueller 2013), SPH (MCG 2003) and WCSPH
 * (Becker & Teschner 2007) on the shared neighbour grid. See include/animkit/fluid.h. */

/* The SIMD kernels give the scalar code's bits only if nothing fuses a * b + c: clang contracts
 * within an expression by default (and avx512f implies FMA); gcc's C11 mode does not. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
#include <animkit/fluid.h>
#include <animkit/grid.h>

#include "fluid/fluid_internal.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>
#include <time.h>

#include "csort.h"
#include "tasks.h"

#define FLUID_PI 3.14159265358979323846
#define FLUID_MAX_THREADS 64u

/* ---- kernels ---------------------------------------------------------------------- */

float ak_fluid_poly6(float r2, float h) {
    const float h2 = h * h;
    if (!(r2 < h2) || !(h > 0.0f)) return 0.0f;
    const float d = h2 - r2;
    const float h9 = h2 * h2 * h2 * h2 * h;
    return (float)(315.0 / (64.0 * FLUID_PI)) / h9 * d * d * d;
}

ak_vec3 ak_fluid_poly6_grad(ak_vec3 r, float h) {
    const float h2 = h * h, r2 = ak_vec3_dot(r, r);
    if (!(r2 < h2) || !(h > 0.0f)) return ak_vec3_make(0.0f, 0.0f, 0.0f);
    const float d = h2 - r2;
    const float h9 = h2 * h2 * h2 * h2 * h;
    return ak_vec3_scale(r, -(float)(945.0 / (32.0 * FLUID_PI)) / h9 * d * d);
}

float ak_fluid_spiky(float r, float h) {
    if (!(r < h) || !(h > 0.0f) || r < 0.0f) return 0.0f;
    const float d = h - r, h3 = h * h * h;
    return (float)(15.0 / FLUID_PI) / (h3 * h3) * d * d * d;
}

ak_vec3 ak_fluid_spiky_grad(ak_vec3 r, float h) {
    const float r2 = ak_vec3_dot(r, r);
    if (!(r2 < h * h) || !(r2 > 0.0f) || !(h > 0.0f)) return ak_vec3_make(0.0f, 0.0f, 0.0f);
    const float len = sqrtf(r2), d = h - len, h3 = h * h * h;
    return ak_vec3_scale(r, -(float)(45.0 / FLUID_PI) / (h3 * h3) * d * d / len);
}

float ak_fluid_visc(float r, float h) {
    if (!(r < h) || !(r > 0.0f) || !(h > 0.0f)) return 0.0f;
    const float q = r / h;
    return (float)(15.0 / (2.0 * FLUID_PI)) / (h * h * h) * (-0.5f * q * q * q + q * q + 0.5f / q - 1.0f);
}

float ak_fluid_visc_laplacian(float r, float h) {
    if (!(r < h) || r < 0.0f || !(h > 0.0f)) return 0.0f;
    const float h3 = h * h * h;
    return (float)(45.0 / FLUID_PI) / (h3 * h3) * (h - r);
}

float ak_fluid_cubic(float r, float h) {
    if (!(r < h) || !(h > 0.0f) || r < 0.0f) return 0.0f;
    const float q = r / h, k = (float)(8.0 / FLUID_PI) / (h * h * h);
    if (q <= 0.5f) return k * (6.0f * (q * q * q - q * q) + 1.0f);
    const float u = 1.0f - q;
    return k * 2.0f * u * u * u;
}

ak_vec3 ak_fluid_cubic_grad(ak_vec3 r, float h) {
    const float r2 = ak_vec3_dot(r, r);
    if (!(r2 < h * h) || !(r2 > 0.0f) || !(h > 0.0f)) return ak_vec3_make(0.0f, 0.0f, 0.0f);
    const float len = sqrtf(r2), q = len / h, k = (float)(48.0 / FLUID_PI) / (h * h * h * h);
    const float u = 1.0f - q;
    const float dw = q <= 0.5f ? k * (3.0f * q * q - 2.0f * q) : -k * u * u;
    return ak_vec3_scale(r, dw / len);
}

/* ---- description ------------------------------------------------------------------ */

static bool desc_ok(const ak_fluid_desc* d) {
    return d && d->h > 0.0f && ak_finitef(d->h) && d->particle_mass > 0.0f && ak_finitef(d->particle_mass) &&
           d->rest_density >= 0.0f && ak_finitef(d->rest_density);
}

/* Neighbour count of a lattice point at rest spacing s (self included), the PBF constraint
 * gradient norm sum_k |grad_k C|^2 there, and its poly6 sum sum_j W(x_j) (1/m^3; times the
 * particle mass it is the density the rest lattice measures). */
static void lattice_props(float h, float s, float m_over_rho, uint32_t* out_count, float* out_grad2, float* out_wsum) {
    const int reach = (int)ceilf(h / s) + 1;
    uint32_t count = 0;
    ak_vec3 gi = {0.0f, 0.0f, 0.0f};
    float sum_gj2 = 0.0f;
    double wsum = 0.0;
    for (int z = -reach; z <= reach; ++z)
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x) {
                ak_vec3 r = ak_vec3_make((float)x * s, (float)y * s, (float)z * s);
                if (ak_vec3_dot(r, r) >= h * h) continue;
                ++count;
                wsum += (double)ak_fluid_poly6(ak_vec3_dot(r, r), h);
                ak_vec3 g = ak_vec3_scale(ak_fluid_spiky_grad(r, h), m_over_rho);
                gi = ak_vec3_add(gi, g);
                sum_gj2 += ak_vec3_dot(g, g);
            }
    *out_count = count;
    *out_grad2 = ak_vec3_dot(gi, gi) + sum_gj2;
    if (out_wsum) *out_wsum = (float)wsum;
}

ak_fluid_desc ak_fluid_desc_resolved(const ak_fluid_desc* desc) {
    ak_fluid_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.rest_density == 0.0f) d.rest_density = 1000.0f;
    if (d.iterations == 0) d.iterations = 4;
    if (d.scorr_k == 0.0f) d.scorr_k = 0.01f;
    if (d.scorr_n == 0.0f) d.scorr_n = 4.0f;
    if (d.scorr_dq == 0.0f) d.scorr_dq = 0.2f;
    if (d.stiffness == 0.0f) d.stiffness = 20.0f;
    if (d.sound_speed == 0.0f) d.sound_speed = 20.0f;
    if (d.tait_gamma == 0.0f) d.tait_gamma = 7.0f;
    if (d.max_neighbours == 0) d.max_neighbours = 96;
    if (d.relaxation == 0.0f && desc_ok(&d)) {
        const float s = cbrtf(d.particle_mass / d.rest_density);
        uint32_t c;
        float g2;
        lattice_props(d.h, s, s * s * s, &c, &g2, NULL);
        d.relaxation = 0.01f * g2;
    }
    return d;
}

float ak_fluid_rest_spacing(const ak_fluid_desc* desc) {
    if (!desc || !(desc->particle_mass > 0.0f) || !ak_finitef(desc->particle_mass) || !(desc->rest_density >= 0.0f) ||
        !ak_finitef(desc->rest_density))
        return 0.0f;
    const float rho0 = desc->rest_density > 0.0f ? desc->rest_density : 1000.0f;
    return cbrtf(desc->particle_mass / rho0);
}

size_t ak_fluid_fill_box(const ak_fluid_desc* desc, ak_vec3 lo, ak_vec3 hi, ak_vec3_span out_positions) {
    const float s = ak_fluid_rest_spacing(desc);
    if (!(s > 0.0f)) return 0;
    if (!ak_finitef(lo.x) || !ak_finitef(lo.y) || !ak_finitef(lo.z) || !ak_finitef(hi.x) || !ak_finitef(hi.y) ||
        !ak_finitef(hi.z))
        return 0;
    const double ex = floor(((double)hi.x - lo.x) / s + 1e-4), ey = floor(((double)hi.y - lo.y) / s + 1e-4),
                 ez = floor(((double)hi.z - lo.z) / s + 1e-4);
    if (!(ex >= 1.0 && ey >= 1.0 && ez >= 1.0) || ex * ey * ez > 1e9) return 0;
    const size_t nx = (size_t)ex, ny = (size_t)ey, nz = (size_t)ez;
    size_t k = 0;
    for (size_t z = 0; z < nz; ++z)
        for (size_t y = 0; y < ny; ++y)
            for (size_t x = 0; x < nx; ++x, ++k)
                if (out_positions.ptr && k < out_positions.count)
                    out_positions.ptr[k] = ak_vec3_make(lo.x + s * (0.5f + (float)x), lo.y + s * (0.5f + (float)y),
                                                        lo.z + s * (0.5f + (float)z));
    return k;
}

/* ---- scratch ---------------------------------------------------------------------- */

typedef struct layout {
    size_t grid, dstart, nb_count, nb, tbuf, order, cell, pred, px, py, pz, qx, qy, qz, p4, q4, x0, v, acc, omega, omega_len, vnew,
        lambda, rho, pres, flags, total;
} layout;

static size_t align64(size_t x) { return (x + 63u) & ~(size_t)63u; }

/* Cells the dense (z, y, x) neighbour search may use for cap particles; a liquid whose
 * bounding box holds more cells of size h takes the shared grid's hashed path. */
static size_t dense_cells(size_t cap) { return 4 * cap + 4096; }

static bool make_layout(size_t cap, const ak_fluid_desc* d, layout* L) {
    if (cap >= ((size_t)1 << 31)) return false;
    ak_grid_desc gd = {.cell_size = d->h};
    size_t gs = ak_grid_memory_size(cap, &gd);
    if (gs == 0) return false;
    const size_t K = d->max_neighbours;
    if (K > ((size_t)1 << 16)) return false;
    size_t o = 0;
#define TAKE(field, bytes) (L->field = o, o = align64(o + (bytes)))
    TAKE(grid, gs);
    TAKE(dstart, (dense_cells(cap) + 1) * 4);
    TAKE(nb_count, cap * 4);
    TAKE(nb, ((cap + 15) & ~(size_t)15) * K * 4); /* blocks of 16 particles, slot-major */
    TAKE(tbuf, AKP_FLUID_MAX_THREADS * (K + 16) * 4);
    TAKE(order, cap * 4);
    TAKE(cell, cap * 4);
    TAKE(pred, cap * sizeof(ak_vec3));
    TAKE(px, cap * 4);
    TAKE(py, cap * 4);
    TAKE(pz, cap * 4);
    TAKE(qx, cap * 4);
    TAKE(qy, cap * 4);
    TAKE(qz, cap * 4);
    TAKE(p4, cap * 16);
    TAKE(q4, cap * 16);
    TAKE(x0, cap * sizeof(ak_vec3));
    TAKE(v, cap * sizeof(ak_vec3));
    TAKE(acc, cap * sizeof(ak_vec3));
    TAKE(omega, cap * sizeof(ak_vec3));
    TAKE(omega_len, cap * 4);
    TAKE(vnew, cap * sizeof(ak_vec3));
    TAKE(lambda, cap * 4);
    TAKE(rho, cap * 4);
    TAKE(pres, cap * 4);
    TAKE(flags, cap);
#undef TAKE
    L->total = o + 64; /* slack to align the base */
    return true;
}

size_t ak_fluid_scratch_size(size_t capacity, const ak_fluid_desc* desc) {
    if (!desc_ok(desc)) return 0;
    ak_fluid_desc d = ak_fluid_desc_resolved(desc);
    layout L;
    if (!make_layout(capacity, &d, &L)) return 0;
    return L.total;
}

ak_fluid_kernels ak_fluid_kernels_resolved(ak_fluid_kernels want) {
    if ((unsigned)want >= AK_FLUID_KERNELS_COUNT) return AK_FLUID_KERNELS_SCALAR;
    if (want == AK_FLUID_KERNELS_BEST) want = AK_FLUID_KERNELS_AVX512;
    if (want == AK_FLUID_KERNELS_AVX512 && !akp_fluid_have_avx512()) want = AK_FLUID_KERNELS_AVX2;
    if (want == AK_FLUID_KERNELS_AVX2 && !akp_fluid_have_avx2()) want = AK_FLUID_KERNELS_SCALAR;
    return want;
}

const char* ak_fluid_kernels_name(ak_fluid_kernels k) {
    switch (k) {
    case AK_FLUID_KERNELS_SCALAR: return "scalar";
    case AK_FLUID_KERNELS_AVX2: return "avx2";
    case AK_FLUID_KERNELS_AVX512: return "avx512";
    default: return "best";
    }
}

/* ---- validation ------------------------------------------------------------------- */

static bool vfinite(ak_vec3 v) { return ak_finitef(v.x) && ak_finitef(v.y) && ak_finitef(v.z); }

/* The particles' data (positions and velocities finite) of [b, e) of the job at ctx: the O(n)
 * part of validation, which ak_fluid_step_run splits over its threads (akp_check_split);
 * 0 or AK_ERR_BAD_DATA. */
static int scan_particles_part(const void* ctx, size_t b, size_t e) {
    const ak_fluid_step_job* job = (const ak_fluid_step_job*)ctx;
    bool ok = true;
    for (size_t i = b; i < e; ++i) ok = vfinite(job->positions.ptr[i]) && vfinite(job->velocities.ptr[i]) && ok;
    return ok ? (int)AK_OK : (int)AK_ERR_BAD_DATA;
}

/* ak_fluid_step_validate; scan_particles false leaves out the particles' data (scan_particles_part). */
static ak_result validate(const ak_fluid_step_job* job, bool scan_particles) {
    if (!job || !job->desc || !job->particle_count || !job->positions.ptr || !job->velocities.ptr ||
        !job->scratch.ptr)
        return AK_ERR_NULL_ARG;
    if ((job->colliders.count && !job->colliders.ptr) || (job->emitters.count && !job->emitters.ptr) ||
        (job->sinks.count && !job->sinks.ptr) || (job->out_densities.count && !job->out_densities.ptr) ||
        (job->out_pressures.count && !job->out_pressures.ptr) || (job->out_flags.count && !job->out_flags.ptr))
        return AK_ERR_NULL_ARG;
    const ak_fluid_desc* d = job->desc;
    if (!desc_ok(d) || !(job->dt > 0.0f) || !ak_finitef(job->dt) || !ak_finitef(job->time) ||
        (unsigned)d->solver >= AK_FLUID_SOLVER_COUNT || (unsigned)job->kernels >= AK_FLUID_KERNELS_COUNT || job->thread_count > FLUID_MAX_THREADS ||
        d->iterations > 1000 || !(d->relaxation >= 0.0f) || !ak_finitef(d->relaxation) || !(d->stiffness >= 0.0f) ||
        !ak_finitef(d->stiffness) || !(d->viscosity >= 0.0f) || !ak_finitef(d->viscosity) ||
        !(d->sound_speed >= 0.0f) || !ak_finitef(d->sound_speed) || !(d->tait_gamma >= 0.0f) ||
        !(d->tait_gamma <= 100.0f) || !(d->friction >= 0.0f) || !(d->friction <= 1.0f) ||
        !ak_finitef(d->scorr_k) || !(d->scorr_n >= 0.0f) || !(d->scorr_n <= 16.0f) || !(d->scorr_dq >= 0.0f) ||
        !(d->scorr_dq < 1.0f) || !(d->xsph_c >= 0.0f) || !(d->xsph_c <= 1.0f) || !ak_finitef(d->vorticity_epsilon) ||
        !vfinite(d->gravity) || !vfinite(d->box_min) || !vfinite(d->box_max) || d->box_min.x > d->box_max.x ||
        d->box_min.y > d->box_max.y || d->box_min.z > d->box_max.z || d->max_neighbours > 65536)
        return AK_ERR_BAD_ARG;
    for (size_t c = 0; c < job->colliders.count; ++c) {
        const ak_fluid_collider* k = &job->colliders.ptr[c];
        if ((unsigned)k->shape >= AK_FLUID_SHAPE_COUNT || !(k->radius >= 0.0f) ||
            !ak_finitef(k->radius) || !vfinite(k->a) || !vfinite(k->b) || !vfinite(k->normal) ||
            !vfinite(k->velocity) || !vfinite(k->angular_velocity) ||
            !ak_quat_is_finite(k->orientation) || !vfinite(k->half_extents) ||
            !(k->half_extents.x >= 0.0f) || !(k->half_extents.y >= 0.0f) ||
            !(k->half_extents.z >= 0.0f))
            return AK_ERR_BAD_ARG;
        if (k->shape == AK_FLUID_HEIGHTFIELD) {
            if (k->rows < 2 || k->cols < 2 || (uint64_t)k->rows * k->cols > (1u << 24) ||
                !(k->spacing > 0.0f) || !ak_finitef(k->spacing))
                return AK_ERR_BAD_ARG;
            if (!k->heights) return AK_ERR_NULL_ARG;
            for (size_t q = 0; q < (size_t)k->rows * k->cols; ++q)
                if (!ak_finitef(k->heights[q])) return AK_ERR_BAD_ARG;
        }
        if (k->shape == AK_FLUID_CONVEX) {
            if (k->plane_count == 0 || k->plane_count > AK_FLUID_CONVEX_MAX_PLANES)
                return AK_ERR_BAD_ARG;
            if (!k->planes) return AK_ERR_NULL_ARG;
            for (uint32_t q = 0; q < k->plane_count; ++q) {
                const ak_vec4 pl = k->planes[q];
                const float l2 = pl.x * pl.x + pl.y * pl.y + pl.z * pl.z;
                if (!ak_finitef(pl.w) || !(fabsf(l2 - 1.0f) <= 2e-3f)) return AK_ERR_BAD_ARG;
            }
        }
    }
    for (size_t e = 0; e < job->emitters.count; ++e) {
        const ak_fluid_emitter* m = &job->emitters.ptr[e];
        if (!(m->speed > 0.0f) || !ak_finitef(m->speed) || !(m->radius >= 0.0f) || !ak_finitef(m->radius) ||
            !vfinite(m->position) || !vfinite(m->direction) || !ak_finitef(m->start_time) ||
            !ak_finitef(m->stop_time) || m->radius > 4096.0f * ak_fluid_rest_spacing(d))
            return AK_ERR_BAD_ARG;
    }
    for (size_t s = 0; s < job->sinks.count; ++s)
        if (!vfinite(job->sinks.ptr[s].min) || !vfinite(job->sinks.ptr[s].max)) return AK_ERR_BAD_ARG;
    const size_t cap = job->positions.count, n = *job->particle_count;
    if (job->velocities.count < cap || n > cap || (job->out_densities.ptr && job->out_densities.count < cap) ||
        (job->out_pressures.ptr && job->out_pressures.count < cap) || (job->out_flags.ptr && job->out_flags.count < cap))
        return AK_ERR_SPAN_SMALL;
    const size_t need = ak_fluid_scratch_size(cap, d);
    if (need == 0) return AK_ERR_BAD_ARG;
    if (job->scratch.count < need) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; scan_particles && i < n; ++i)
        if (!vfinite(job->positions.ptr[i]) || !vfinite(job->velocities.ptr[i])) return AK_ERR_BAD_DATA;
    return AK_OK;
}

ak_result ak_fluid_step_validate(const ak_fluid_step_job* job) { return validate(job, true); }

/* ---- the solver ------------------------------------------------------------------- */
/* ---- the solver ------------------------------------------------------------------- */

typedef akp_fluid_ctx ctx;

/* The public kernels with their constants computed once per step (same float operations). */
static inline float k_poly6(const ctx* c, float r2) {
    if (!(r2 < c->h2)) return 0.0f;
    const float d = c->h2 - r2;
    return c->poly6_k * d * d * d;
}

static inline ak_vec3 k_spiky(const ctx* c, ak_vec3 r) {
    const float r2 = ak_vec3_dot(r, r);
    if (!(r2 < c->h2) || !(r2 > 0.0f)) return ak_vec3_make(0.0f, 0.0f, 0.0f);
    const float len = sqrtf(r2), d = c->h - len;
    return ak_vec3_scale(r, c->spiky_k * d * d / len);
}

/* The cubic spline and its gradient (ak_fluid_cubic, ak_fluid_cubic_grad) with the step's
 * constants: the same formulas, not the same bits. */
static inline float k_cubic(const ctx* c, float r2) {
    if (!(r2 < c->h2)) return 0.0f;
    const float q = sqrtf(r2) * c->inv_h;
    if (q <= 0.5f) return c->cubic_k * (6.0f * (q * q * q - q * q) + 1.0f);
    const float u = 1.0f - q;
    return c->cubic_k * 2.0f * u * u * u;
}

static inline ak_vec3 k_cubic_grad(const ctx* c, ak_vec3 r) {
    const float r2 = ak_vec3_dot(r, r);
    if (!(r2 < c->h2) || !(r2 > 0.0f)) return ak_vec3_make(0.0f, 0.0f, 0.0f);
    const float len = sqrtf(r2), q = len * c->inv_h, u = 1.0f - q;
    const float dw = q <= 0.5f ? c->cubic_gk * (3.0f * q * q - 2.0f * q) : -c->cubic_gk * u * u;
    return ak_vec3_scale(r, dw / len);
}

/* Predicted position of sorted particle a. */
static inline ak_vec3 P(const ctx* c, uint32_t a) { return ak_vec3_make(c->px[a], c->py[a], c->pz[a]); }

typedef void (*phase_fn)(ctx* c, size_t begin, size_t end, uint32_t t);

/* The end-of-step statistics of one chunk of STATS_CHUNK sorted particles. */
#define STATS_CHUNK 1024u
typedef struct akp_fluid_stats_part {
    double sum_err, sum_rho;
    float max_err;
    uint32_t surface, full;
    bool blown;
} stats_part;

/* Start of thread t's share of [0, n): a multiple of 16 (whole blocks of neighbour lists). */
static size_t split(size_t n, uint32_t t, uint32_t threads) {
    return t >= threads ? n : (n * t / threads) & ~(size_t)15;
}

/* The step's team: thread_count - 1 of the library's workers (src/tasks.h) lent for the
 * whole step (not once per phase: a PBF step has about 20 phases); they run each phase's share
 * and meet the caller at a barrier before and after it. */
typedef struct akp_fluid_team {
    akp_barrier bar;
    akp_team_run run;
    uint32_t size; /* threads meeting at the barrier, the caller included */
    /* the phase being run (written by the caller before the start barrier) */
    phase_fn fn;
    size_t n;
    bool quit;
} team;

typedef struct worker {
    ctx* c;
    uint32_t t;
} worker;

static void* worker_main(void* arg) {
    const worker* w = (const worker*)arg;
    team* tm = w->c->team;
    for (;;) {
        akp_barrier_wait(&tm->bar); /* start of a phase (or quit) */
        if (tm->quit) return NULL;
        tm->fn(w->c, split(tm->n, w->t, tm->size), split(tm->n, w->t + 1, tm->size), w->t);
        akp_barrier_wait(&tm->bar); /* end of the phase */
    }
}

/* Lends threads - 1 workers to the step; c->team stays NULL when they cannot all run (the
 * caller then runs every phase alone). */
static void team_start(ctx* c, team* tm, worker* ws, uint32_t threads) {
    memset(tm, 0, sizeof *tm);
    if (threads < 2) return;
    tm->size = threads;
    akp_barrier_init(&tm->bar, threads);
    for (uint32_t t = 0; t < threads; ++t) ws[t] = (worker){c, t};
    c->team = tm; /* before the workers read it */
    if (!akp_team_begin(&tm->run, worker_main, ws, sizeof(worker), threads)) {
        akp_barrier_destroy(&tm->bar);
        c->team = NULL;
    }
}

static void team_stop(ctx* c) {
    team* tm = c->team;
    if (!tm) return;
    tm->quit = true;
    akp_barrier_wait(&tm->bar);
    akp_team_end(&tm->run);
    akp_barrier_destroy(&tm->bar);
    c->team = NULL;
}

/* Runs fn over [0, n) split in equal contiguous chunks over the team; the split never changes
 * a result (every phase writes only its own particles' values). */
static void parallel_n(ctx* c, phase_fn fn, size_t n) {
    team* tm = c->team;
    if (!tm) {
        fn(c, 0, n, 0);
        return;
    }
    tm->fn = fn, tm->n = n;
    akp_barrier_wait(&tm->bar);
    fn(c, split(n, 0, tm->size), split(n, 1, tm->size), 0);
    akp_barrier_wait(&tm->bar);
}

static void parallel(ctx* c, phase_fn fn) { parallel_n(c, fn, c->n); }

/* A heightfield collider at p: p in its frame (*l), the surface's height under it (*y) and the
 * upward unit normal of that triangle (*n, in the frame); false when p is off the grid. */
static bool heightfield_surface(const ak_fluid_collider* col, ak_quat q, ak_vec3 p, ak_vec3* l,
                                float* y, ak_vec3* n) {
    *l = ak_quat_rotate(ak_quat_conjugate(q), ak_vec3_sub(p, col->a));
    const float fx = l->x / col->spacing, fz = l->z / col->spacing;
    if (!(fx >= 0.0f) || !(fz >= 0.0f) || fx > (float)(col->cols - 1) ||
        fz > (float)(col->rows - 1))
        return false;
    uint32_t i = (uint32_t)fx, j = (uint32_t)fz;
    if (i > col->cols - 2) i = col->cols - 2;
    if (j > col->rows - 2) j = col->rows - 2;
    const float u = fx - (float)i, v = fz - (float)j, s = col->spacing;
    const float* hr = col->heights + (size_t)j * col->cols + i;
    const float h00 = hr[0], h10 = hr[1], h01 = hr[col->cols], h11 = hr[col->cols + 1];
    /* rigid.h's split: (00, 01, 11) where v >= u, else (00, 11, 10); the surface over the
     * triangle is h00 + a u + b v, its upward normal (-a/s, 1, -b/s) */
    const float a = v >= u ? h11 - h01 : h10 - h00, b = v >= u ? h01 - h00 : h11 - h10;
    *y = h00 + a * u + b * v;
    *n = ak_vec3_normalize(ak_vec3_make(-a / s, 1.0f, -b / s));
    return true;
}

/* Rotation of a box or convex collider's frame (zero -> identity). */
static ak_quat collider_rotation(const ak_fluid_collider* col) {
    const ak_quat q = col->orientation;
    return ak_quat_dot(q, q) > 0.0f ? ak_quat_normalize(q) : ak_quat_identity();
}

/* Signed distance from p to a collider's surface (negative inside; for a convex polytope
 * outside it, the largest plane distance: a lower bound) and, when p is inside, *out_n the
 * outward normal of the nearest surface point (p + n * -distance). */
static float collider_distance(const ak_fluid_collider* col, ak_vec3 p, ak_vec3* out_n) {
    switch (col->shape) {
    case AK_FLUID_PLANE: {
        ak_vec3 n = ak_vec3_length_sq(col->normal) > 0.0f ? ak_vec3_normalize(col->normal)
                                                          : ak_vec3_make(0, 1, 0);
        *out_n = n;
        return ak_vec3_dot(ak_vec3_sub(p, col->a), n);
    }
    case AK_FLUID_BOX: {
        const ak_quat q = collider_rotation(col);
        const ak_vec3 l = ak_quat_rotate(ak_quat_conjugate(q), ak_vec3_sub(p, col->a));
        const float lc[3] = {l.x, l.y, l.z},
                    hc[3] = {col->half_extents.x, col->half_extents.y, col->half_extents.z};
        float out2 = 0.0f, inside = -INFINITY;
        int axis = 0;
        for (int k = 0; k < 3; ++k) {
            const float e = fabsf(lc[k]) - hc[k];
            if (e > 0.0f) out2 += e * e;
            if (e > inside) inside = e, axis = k;
        }
        if (out2 > 0.0f) {
            *out_n = ak_vec3_make(0, 1, 0);
            return sqrtf(out2);
        }
        float nl[3] = {0.0f, 0.0f, 0.0f};
        nl[axis] = lc[axis] < 0.0f ? -1.0f : 1.0f;
        *out_n = ak_quat_rotate(q, ak_vec3_make(nl[0], nl[1], nl[2]));
        return inside;
    }
    case AK_FLUID_CONVEX: {
        const ak_quat q = collider_rotation(col);
        const ak_vec3 l = ak_quat_rotate(ak_quat_conjugate(q), ak_vec3_sub(p, col->a));
        float best = -INFINITY;
        uint32_t face = 0;
        for (uint32_t k = 0; k < col->plane_count; ++k) {
            const ak_vec4 pl = col->planes[k];
            const float e = pl.x * l.x + pl.y * l.y + pl.z * l.z - pl.w;
            if (e > best) best = e, face = k;
        }
        const ak_vec4 pl = col->planes[face];
        *out_n = ak_quat_rotate(q, ak_vec3_make(pl.x, pl.y, pl.z));
        return best;
    }
    case AK_FLUID_HEIGHTFIELD: {
        ak_vec3 l, n;
        float y;
        const ak_quat q = collider_rotation(col);
        *out_n = ak_quat_rotate(q, ak_vec3_make(0, 1, 0));
        if (!heightfield_surface(col, q, p, &l, &y, &n)) return INFINITY; /* off the grid */
        *out_n = ak_quat_rotate(q, n);
        return (l.y - y) * n.y; /* the distance to the triangle's plane */
    }
    default: {
        ak_vec3 q = col->a;
        if (col->shape == AK_FLUID_CAPSULE) {
            ak_vec3 ab = ak_vec3_sub(col->b, col->a);
            float l2 = ak_vec3_dot(ab, ab);
            float t = l2 > 0.0f ? ak_vec3_dot(ak_vec3_sub(p, col->a), ab) / l2 : 0.0f;
            t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
            q = ak_vec3_add(col->a, ak_vec3_scale(ab, t));
        }
        ak_vec3 r = ak_vec3_sub(p, q);
        float len = ak_vec3_length(r);
        *out_n = len > 1e-12f ? ak_vec3_scale(r, 1.0f / len) : ak_vec3_make(0, 1, 0);
        return len - col->radius;
    }
    }
}

/* One pass over the colliders; true when one of them moved p. */
static bool collide_pass(const ctx* c, ak_vec3* p, ak_vec3* v) {
    const ak_fluid_desc* d = &c->d;
    const ak_fluid_step_job* job = c->job;
    bool moved = false;
    for (size_t k = 0; k < job->colliders.count; ++k) {
        const ak_fluid_collider* col = &job->colliders.ptr[k];
        ak_vec3 n;
        const float depth = -collider_distance(col, *p, &n);
        if (!(depth > 0.0f)) continue;
        moved = true;
        *p = ak_vec3_add(*p, ak_vec3_scale(n, depth));
        if (col->shape == AK_FLUID_HEIGHTFIELD) {
            /* along the normal p may have crossed into a neighbouring triangle and still be
             * under it (a valley): then straight up onto the surface, which is exact */
            ak_vec3 l, nl;
            float y;
            const ak_quat q = collider_rotation(col);
            if (heightfield_surface(col, q, *p, &l, &y, &nl) && l.y < y) {
                l.y = y;
                *p = ak_vec3_add(col->a, ak_quat_rotate(q, l));
            }
        }
        if (v) {
            /* the surface's velocity at the projected point */
            const ak_vec3 vs = ak_vec3_add(
                col->velocity, ak_vec3_cross(col->angular_velocity, ak_vec3_sub(*p, col->a)));
            ak_vec3 rel = ak_vec3_sub(*v, vs);
            float vn = ak_vec3_dot(rel, n);
            if (vn < 0.0f) {
                ak_vec3 vt = ak_vec3_sub(rel, ak_vec3_scale(n, vn));
                *v = ak_vec3_add(vs, ak_vec3_scale(vt, 1.0f - d->friction));
            }
        }
    }
    return moved;
}

/* The box container: p clamped inside, v loses its outward components. */
static void collide_box(const ctx* c, ak_vec3* p, ak_vec3* v) {
    const ak_fluid_desc* d = &c->d;
    if (d->box_min.x < d->box_max.x || d->box_min.y < d->box_max.y || d->box_min.z < d->box_max.z) {
        float* pc = &p->x;
        float* vc = v ? &v->x : NULL;
        const float* lo = &d->box_min.x;
        const float* hi = &d->box_max.x;
        bool hit = false;
        for (int a = 0; a < 3; ++a) {
            if (pc[a] < lo[a]) {
                pc[a] = lo[a];
                if (vc && vc[a] < 0.0f) vc[a] = 0.0f;
                hit = true;
            } else if (pc[a] > hi[a]) {
                pc[a] = hi[a];
                if (vc && vc[a] > 0.0f) vc[a] = 0.0f;
                hit = true;
            }
        }
        if (hit && vc && d->friction > 0.0f) {
            for (int a = 0; a < 3; ++a)
                if (pc[a] > lo[a] && pc[a] < hi[a]) vc[a] *= 1.0f - d->friction;
        }
    }
}

/* Collider projection: moves p outside every collider and inside the box; v (may be NULL)
 * loses its inward normal component relative to the collider, friction scales the rest.
 * Colliders are visited in order; a particle squeezed between two of them can be pushed back
 * into the first by the second, so the pass repeats (at most 4 times) while a collider moved
 * it. */
void akp_fluid_collide(const ctx* c, ak_vec3* p, ak_vec3* v) {
    const ak_fluid_step_job* job = c->job;
    for (int pass = 0; pass < 4; ++pass)
        if (!collide_pass(c, p, v) || job->colliders.count < 2) break;
    collide_box(c, p, v);
}

/* Distance from p to the nearest boundary surface (box walls and colliders). */
static float boundary_distance(const ctx* c, ak_vec3 p) {
    const ak_fluid_desc* d = &c->d;
    float best = INFINITY;
    if (d->box_min.x < d->box_max.x || d->box_min.y < d->box_max.y || d->box_min.z < d->box_max.z) {
        const float* pc = &p.x;
        const float* lo = &d->box_min.x;
        const float* hi = &d->box_max.x;
        for (int a = 0; a < 3; ++a) {
            float e = fminf(pc[a] - lo[a], hi[a] - pc[a]);
            if (e < best) best = e;
        }
    }
    for (size_t k = 0; k < c->job->colliders.count; ++k) {
        ak_vec3 n;
        const float e = collider_distance(&c->job->colliders.ptr[k], p, &n);
        if (e < best) best = e;
    }
    return best;
}

/* ---- neighbour search ------------------------------------------------------------- */

/* The grid's cell formula: floor(p / h) in double, clamped to +-2^30 as grid.h does. */
static inline int64_t cell_coord(const ctx* c, float p) {
    double v = floor((double)p * c->inv_cell);
    v = v < -1073741824.0 ? -1073741824.0 : v > 1073741824.0 ? 1073741824.0 : v;
    return (int64_t)v;
}

/* Appends the candidates [begin, end) within h of q to list (capacity K, index order); adds
 * to *close those within sqrt(coincident2) (q's own particle included). */
static inline uint32_t filter_scalar(const ctx* c, uint32_t begin, uint32_t end, float qx, float qy, float qz,
                                     uint32_t* list, uint32_t* k, uint32_t* close) {
    const float r2 = c->h2;
    uint32_t found = 0;
    for (uint32_t bq = begin; bq < end; ++bq) {
        const float ddx = c->px[bq] - qx, ddy = c->py[bq] - qy, ddz = c->pz[bq] - qz;
        const float dd = ddx * ddx + ddy * ddy + ddz * ddz;
        if (dd < r2) {
            if (*k < c->K) list[(*k)++] = bq;
            ++found;
            if (dd < c->coincident2) ++*close;
        }
    }
    return found;
}

/* Copies particle a's list into the slot-major layout (see akp_fluid_nb). */
static void store_list(ctx* c, size_t a, const uint32_t* list, uint32_t k) {
    uint32_t* dst = c->nb + (a >> 4) * c->K * 16 + (a & 15);
    for (uint32_t q = 0; q < k; ++q) dst[(size_t)q * 16] = list[q];
    c->nb_count[a] = k;
}

/* Dense path, sorted particles [b, e): the 3 x 3 rows of cells around a particle's cell, each
 * a contiguous range of sorted indices (cells in (z, y, x) order), scanned z, then y, then x,
 * each cell in index order: the order of the hashed path's 27 cell lookups. */
static void ph_neighbours_dense(ctx* c, size_t b, size_t e, uint32_t t) {
    size_t trunc = 0, coincident = 0;
    const int64_t X = c->dim[0], Y = c->dim[1], Z = c->dim[2];
    for (size_t a = b; a < e; ++a) {
        const float qx = c->px[a], qy = c->py[a], qz = c->pz[a];
        const int64_t cx = cell_coord(c, qx) - c->cmin[0], cy = cell_coord(c, qy) - c->cmin[1],
                      cz = cell_coord(c, qz) - c->cmin[2];
        const int64_t xa = cx > 0 ? cx - 1 : 0, xb = cx + 1 < X ? cx + 1 : X - 1;
        uint32_t* list = c->tbuf + (size_t)t * (c->K + 16);
        uint32_t k = 0, total = 0, close = 0;
        for (int64_t zz = cz - 1; zz <= cz + 1; ++zz) {
            if (zz < 0 || zz >= Z) continue;
            for (int64_t yy = cy - 1; yy <= cy + 1; ++yy) {
                if (yy < 0 || yy >= Y) continue;
                const size_t row = (size_t)((zz * Y + yy) * X);
                const uint32_t rb = c->dstart[row + (size_t)xa], re = c->dstart[row + (size_t)xb + 1];
                if (rb == re) continue;
                total += c->kernels == AK_FLUID_KERNELS_AVX512
                             ? akp_fluid_filter_avx512(c, rb, re, qx, qy, qz, list, &k, &close)
                         : c->kernels == AK_FLUID_KERNELS_AVX2
                             ? akp_fluid_filter_avx2(c, rb, re, qx, qy, qz, list, &k, &close)
                             : filter_scalar(c, rb, re, qx, qy, qz, list, &k, &close);
            }
        }
        if (total > c->K) ++trunc;
        if (close > 1) ++coincident;
        store_list(c, a, list, k);
    }
    c->truncated[t] = trunc;
    c->coincident[t] = coincident;
}

/* Hashed path, grid cells [b, e): every point of a cell scans the 27 cells around it (fixed
 * order z, y, x), each in sorted order. */
static void ph_neighbours_hashed(ctx* c, size_t b, size_t e, uint32_t t) {
    const ak_grid* g = &c->grid;
    size_t trunc = 0, coincident = 0;
    uint32_t around[27];
    for (size_t m = b; m < e; ++m) {
        const ak_grid_cell cc = g->cell_coord[m];
        int na = 0;
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    uint32_t m2 = ak_grid_cell_find(g, (ak_grid_cell){cc.x + dx, cc.y + dy, cc.z + dz});
                    if (m2 != UINT32_MAX) around[na++] = m2;
                }
        for (uint32_t a = g->cell_start[m]; a < g->cell_start[m + 1]; ++a) {
            const float qx = c->px[a], qy = c->py[a], qz = c->pz[a];
            uint32_t* list = c->tbuf + (size_t)t * (c->K + 16);
            uint32_t k = 0, total = 0, close = 0;
            for (int q = 0; q < na; ++q)
                total += filter_scalar(c, g->cell_start[around[q]], g->cell_start[around[q] + 1], qx, qy, qz, list,
                                       &k, &close);
            if (total > c->K) ++trunc;
            if (close > 1) ++coincident;
            store_list(c, a, list, k);
        }
    }
    c->truncated[t] = trunc;
    c->coincident[t] = coincident;
}

/* Pads every list of blocks [b, e) (16-aligned) up to its block's longest list with index 0,
 * and the lists of lanes past n likewise, so the AVX-512 kernels may read the 16 entries of any
 * slot below the block's longest count (the pads are masked out of every sum). */
static void ph_pad_lists(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t blk = b; blk < e; blk += 16) {
        uint32_t top = 0, cnt[16];
        for (uint32_t u = 0; u < 16; ++u) {
            cnt[u] = blk + u < c->n ? c->nb_count[blk + u] : 0u;
            top = cnt[u] > top ? cnt[u] : top;
        }
        uint32_t* base = c->nb + (blk >> 4) * c->K * 16;
        for (uint32_t u = 0; u < 16; ++u)
            for (uint32_t q = cnt[u]; q < top; ++q) base[(size_t)q * 16 + u] = 0;
    }
}

/* Sorts the predicted positions c->pred by cell into c->order / px, py, pz. Dense (z, y, x)
 * cells when the bounding box holds at most dense_cells(cap) cells, else the shared grid.
 * Returns false on a non-finite prediction. Sets *dense. */
/* The predictions' bounds over [b, e), per thread (min and max: any split gives the same box). */
static void ph_bounds(ctx* c, size_t b, size_t e, uint32_t t) {
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    bool bad = false;
    for (size_t i = b; i < e; ++i) {
        const float* p = &c->pred[i].x;
        for (int a = 0; a < 3; ++a) {
            bad = bad || !ak_finitef(p[a]);
            lo[a] = p[a] < lo[a] ? p[a] : lo[a];
            hi[a] = p[a] > hi[a] ? p[a] : hi[a];
        }
    }
    for (int a = 0; a < 3; ++a) c->box_lo[t][a] = lo[a], c->box_hi[t][a] = hi[a];
    c->box_bad[t] = bad;
}

/* Each particle's dense cell, (z, y, x) order. */
static void ph_cell_keys(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t i = b; i < e; ++i) {
        const ak_vec3 p = c->pred[i];
        const int64_t x = cell_coord(c, p.x) - c->cmin[0], y = cell_coord(c, p.y) - c->cmin[1],
                      z = cell_coord(c, p.z) - c->cmin[2];
        c->cell[i] = (uint32_t)((z * c->dim[1] + y) * c->dim[0] + x);
    }
}

static void ph_csort_count(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)b, (void)e;
    akp_csort_count(c->csort, t);
}

static void ph_csort_scatter(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)b, (void)e;
    akp_csort_scatter(c->csort, t);
}

static void ph_csort_finish(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)b, (void)e;
    akp_csort_finish(c->csort, t);
}

/* The predictions in sorted order. */
static void ph_sorted_positions(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t a = b; a < e; ++a) {
        const ak_vec3 p = c->pred[c->order[a]];
        c->px[a] = p.x, c->py[a] = p.y, c->pz[a] = p.z;
        if (c->simd) c->p4[4 * a] = p.x, c->p4[4 * a + 1] = p.y, c->p4[4 * a + 2] = p.z, c->p4[4 * a + 3] = 0.0f;
    }
}

/* Sort the predictions by cell: the dense (z, y, x) box of cells when it fits dense_cells, a
 * stable counting sort over the team (src/csort.h: index order within a cell, for any thread
 * count), else the shared hashed grid (one thread). False when a prediction is not finite. */
static bool sort_by_cell(ctx* c, uint8_t* grid_mem, size_t grid_bytes, size_t cap, bool* dense) {
    const size_t n = c->n;
    const uint32_t T = c->team ? c->team->size : 1u;
    parallel(c, ph_bounds);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = 0; t < T; ++t) {
        if (c->box_bad[t]) return false;
        for (int a = 0; a < 3; ++a) {
            lo[a] = c->box_lo[t][a] < lo[a] ? c->box_lo[t][a] : lo[a];
            hi[a] = c->box_hi[t][a] > hi[a] ? c->box_hi[t][a] : hi[a];
        }
    }
    double volume = n ? 1.0 : 0.0;
    for (int a = 0; a < 3 && n; ++a) {
        c->cmin[a] = cell_coord(c, lo[a]);
        c->dim[a] = cell_coord(c, hi[a]) - c->cmin[a] + 1;
        volume *= (double)c->dim[a];
    }
    *dense = n > 0 && volume <= (double)dense_cells(cap) && volume < 4294967295.0;
    if (*dense) {
        parallel(c, ph_cell_keys);
        akp_csort cs = {.keys = c->cell, .n = n, .buckets = (uint32_t)volume, .order = c->order, .start = c->dstart};
        /* the grid's memory (unused on this path) holds the sort's 2 n scratch */
        uint32_t* tmp = (uint32_t*)(void*)(((uintptr_t)grid_mem + 3u) & ~(uintptr_t)3u);
        cs.parts = T > 1 && grid_bytes >= 8 * n + 8 ? T : 1u;
        cs.tmp = tmp;
        c->csort = &cs;
        if (cs.parts > 1) {
            parallel(c, ph_csort_count);
            akp_csort_offsets(&cs);
            parallel(c, ph_csort_scatter);
            parallel(c, ph_csort_finish);
        } else {
            akp_csort_offsets(&cs);
            akp_csort_finish(&cs, 0);
        }
        c->csort = NULL;
    } else {
        ak_grid_desc gd = {.cell_size = c->h};
        if (ak_grid_build(&gd, (ak_vec3_cspan){c->pred, n}, (ak_u8_span){grid_mem, grid_bytes}, &c->grid) != AK_OK)
            return false;
        memcpy(c->order, c->grid.order, n * sizeof(uint32_t));
    }
    parallel(c, ph_sorted_positions);
    return true;
}

/* ---- phases (sorted particles [b, e)) ---------------------------------------------- */

static void ph_predict(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const float dt = c->dt;
    for (size_t i = b; i < e; ++i) {
        if (c->d.solver == AK_FLUID_PBF) {
            c->vo[i] = ak_vec3_add(c->vo[i], ak_vec3_scale(c->d.gravity, dt));
            ak_vec3 p = ak_vec3_add(c->xo[i], ak_vec3_scale(c->vo[i], dt));
            akp_fluid_collide(c, &p, NULL);
            c->pred[i] = p;
        } else {
            c->pred[i] = c->xo[i];
        }
    }
}

/* Start positions and velocities into sorted order. */
static void ph_gather(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t a = b; a < e; ++a) {
        const uint32_t i = c->order[a];
        c->x0[a] = c->xo[i];
        c->v[a] = c->vo[i];
        c->pres[a] = 0.0f; /* PBF sums lambdas here */
    }
}

static void ph_density(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const bool cubic = c->d.solver == AK_FLUID_WCSPH;
    if (c->simd) {
        if (cubic) (c->kernels == AK_FLUID_KERNELS_AVX512 ? akp_fluid_density_cubic_avx512 : akp_fluid_density_cubic_avx2)(c, b, e);
        else (c->kernels == AK_FLUID_KERNELS_AVX512 ? akp_fluid_density_avx512 : akp_fluid_density_avx2)(c, b, e);
        return;
    }
    for (size_t i = b; i < e; ++i) {
        const uint32_t* nb = akp_fluid_nb(c, i);
        const ak_vec3 pi = P(c, (uint32_t)i);
        float rho = 0.0f;
        for (uint32_t q = 0; q < c->nb_count[i]; ++q) {
            ak_vec3 r = ak_vec3_sub(pi, P(c, nb[(size_t)q * 16]));
            rho += cubic ? k_cubic(c, ak_vec3_dot(r, r)) : k_poly6(c, ak_vec3_dot(r, r));
        }
        c->rho[i] = rho * c->m;
    }
}

/* PBF: density and lambda_i = -C_i / (sum_k |grad_k C_i|^2 + epsilon). */
static void ph_lambda(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    if (c->simd) {
        (c->kernels == AK_FLUID_KERNELS_AVX512 ? akp_fluid_lambda_avx512 : akp_fluid_lambda_avx2)(c, b, e);
        return;
    }
    for (size_t i = b; i < e; ++i) {
        const uint32_t* nb = akp_fluid_nb(c, i);
        const ak_vec3 pi = P(c, (uint32_t)i);
        float rho = 0.0f, sum_gj2 = 0.0f;
        ak_vec3 gi = {0.0f, 0.0f, 0.0f};
        for (uint32_t q = 0; q < c->nb_count[i]; ++q) {
            ak_vec3 r = ak_vec3_sub(pi, P(c, nb[(size_t)q * 16]));
            rho += k_poly6(c, ak_vec3_dot(r, r));
            ak_vec3 g = ak_vec3_scale(k_spiky(c, r), c->mr);
            gi = ak_vec3_add(gi, g);
            sum_gj2 += ak_vec3_dot(g, g);
        }
        rho *= c->m;
        c->rho[i] = rho;
        float C = rho / c->rho_c - 1.0f;
        if (!c->d.bilateral && C < 0.0f) C = 0.0f;
        c->lambda[i] = -C / (ak_vec3_dot(gi, gi) + sum_gj2 + c->d.relaxation);
    }
}

/* PBF: dp_i = (m/rho0) sum_j (lambda_i + lambda_j + s_corr) grad W(p_i - p_j), then the
 * collision response on p_i + dp_i, written to q (the next iterate). */
static void ph_delta(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const bool scorr = c->d.scorr && c->wdq > 0.0f;
    const float k = c->d.scorr_k / c->grad2_rest, np = c->d.scorr_n, inv_wdq = scorr ? 1.0f / c->wdq : 0.0f;
    const bool n4 = np == 4.0f;
    if (c->simd && (n4 || !scorr)) {
        (c->kernels == AK_FLUID_KERNELS_AVX512 ? akp_fluid_delta_avx512 : akp_fluid_delta_avx2)(c, b, e);
        return;
    }
    for (size_t i = b; i < e; ++i) {
        const uint32_t* nb = akp_fluid_nb(c, i);
        const ak_vec3 pi = P(c, (uint32_t)i);
        const float li = c->lambda[i];
        ak_vec3 acc = {0.0f, 0.0f, 0.0f};
        for (uint32_t q = 0; q < c->nb_count[i]; ++q) {
            const uint32_t j = nb[(size_t)q * 16];
            if (j == i) continue;
            ak_vec3 r = ak_vec3_sub(pi, P(c, j));
            float s = 0.0f;
            if (scorr) {
                float w = k_poly6(c, ak_vec3_dot(r, r)) * inv_wdq;
                float w2 = w * w;
                s = -k * (n4 ? w2 * w2 : powf(w, np));
            }
            acc = ak_vec3_add(acc, ak_vec3_scale(k_spiky(c, r), li + c->lambda[j] + s));
        }
        akp_fluid_delta_finish(c, i, ak_vec3_add(pi, ak_vec3_scale(acc, c->mr)));
    }
}

void akp_fluid_delta_finish(akp_fluid_ctx* c, size_t i, ak_vec3 p) {
    c->pres[i] += c->lambda[i]; /* sum of the step's lambdas: the pressure, see ph_velocity */
    akp_fluid_collide(c, &p, NULL);
    c->qx[i] = p.x, c->qy[i] = p.y, c->qz[i] = p.z;
    /* the SIMD kernels' next iterate as (x, y, z, 0) records: no pass reads p4 until the next
     * lambda pass (the correction pass reads q4) */
    if (c->simd) c->p4[4 * i] = p.x, c->p4[4 * i + 1] = p.y, c->p4[4 * i + 2] = p.z, c->p4[4 * i + 3] = 0.0f;
}

/* PBF: v = (x* - x) / dt, and the pressure the step's corrections stand for. A correction
 * (m/rho_0) sum_j (lambda_i + lambda_j) grad W_ij over one step is the displacement dt^2 a of
 * the symmetric SPH pressure acceleration -(m/rho_0^2) sum_j (p_i + p_j) grad W_ij, so
 * p_i = -rho_0 sum_iterations lambda_i / dt^2 (Pa). */
static void ph_velocity(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const float inv_dt = 1.0f / c->dt, pk = -c->rho0 / (c->dt * c->dt);
    for (size_t i = b; i < e; ++i) {
        c->v[i] = ak_vec3_scale(ak_vec3_sub(P(c, (uint32_t)i), c->x0[i]), inv_dt);
        c->pres[i] *= pk;
    }
}

/* AVX-512 PBF: (v, rho) records into q4 for the vorticity and XSPH kernels. */
static void ph_pack_v(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t i = b; i < e; ++i)
        c->q4[4 * i] = c->v[i].x, c->q4[4 * i + 1] = c->v[i].y, c->q4[4 * i + 2] = c->v[i].z, c->q4[4 * i + 3] = c->rho[i];
}

/* PBF: vorticity omega_i = sum_j (m / rho_j) v_ij x grad_j W_ij (1/s). */
static void ph_vorticity(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    if (c->simd) {
        (c->kernels == AK_FLUID_KERNELS_AVX512 ? akp_fluid_vorticity_avx512 : akp_fluid_vorticity_avx2)(c, b, e);
        return;
    }
    for (size_t i = b; i < e; ++i) {
        const uint32_t* nb = akp_fluid_nb(c, i);
        ak_vec3 w = {0.0f, 0.0f, 0.0f};
        for (uint32_t q = 0; q < c->nb_count[i]; ++q) {
            const uint32_t j = nb[(size_t)q * 16];
            ak_vec3 vij = ak_vec3_sub(c->v[j], c->v[i]);
            /* grad_{p_j} W(p_i - p_j) = -grad W(p_i - p_j) */
            ak_vec3 g = ak_vec3_neg(k_spiky(c, ak_vec3_sub(P(c, (uint32_t)i), P(c, j))));
            if (c->rho[j] > 0.0f) w = ak_vec3_add(w, ak_vec3_scale(ak_vec3_cross(vij, g), c->m / c->rho[j]));
        }
        c->omega[i] = w;
        c->omega_len[i] = ak_vec3_length(w);
    }
}

/* PBF: vorticity confinement f = eps (N x omega), N = eta / |eta|, eta = grad |omega|, and
 * XSPH v_i += c sum_j (m / rho_j) v_ij W_ij (the paper drops m / rho_j with its unit mass),
 * both from the same velocity snapshot. */
static void ph_xsph(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    if (c->simd) {
        (c->kernels == AK_FLUID_KERNELS_AVX512 ? akp_fluid_xsph_avx512 : akp_fluid_xsph_avx2)(c, b, e);
        return;
    }
    const float eps = c->d.vorticity_epsilon, xc = c->d.xsph_c;
    for (size_t i = b; i < e; ++i) {
        const uint32_t* nb = akp_fluid_nb(c, i);
        const ak_vec3 pi = P(c, (uint32_t)i);
        ak_vec3 eta = {0.0f, 0.0f, 0.0f}, xs = {0.0f, 0.0f, 0.0f};
        for (uint32_t q = 0; q < c->nb_count[i]; ++q) {
            const uint32_t j = nb[(size_t)q * 16];
            ak_vec3 r = ak_vec3_sub(pi, P(c, j));
            if (eps != 0.0f && c->rho[j] > 0.0f)
                eta = ak_vec3_add(eta, ak_vec3_scale(k_spiky(c, r), c->m / c->rho[j] * c->omega_len[j]));
            if (xc != 0.0f && c->rho[j] > 0.0f)
                xs = ak_vec3_add(xs, ak_vec3_scale(ak_vec3_sub(c->v[j], c->v[i]),
                                                   c->m / c->rho[j] * k_poly6(c, ak_vec3_dot(r, r))));
        }
        akp_fluid_xsph_finish(c, i, eta, xs);
    }
}

void akp_fluid_xsph_finish(akp_fluid_ctx* c, size_t i, ak_vec3 eta, ak_vec3 xs) {
    const float eps = c->d.vorticity_epsilon;
    ak_vec3 vi = ak_vec3_add(c->v[i], ak_vec3_scale(xs, c->d.xsph_c));
    if (eps != 0.0f) {
        float el = ak_vec3_length(eta);
        if (el > 1e-20f) {
            ak_vec3 N = ak_vec3_scale(eta, 1.0f / el);
            vi = ak_vec3_add(vi, ak_vec3_scale(ak_vec3_cross(N, c->omega[i]), eps * c->dt));
        }
    }
    c->vnew[i] = vi;
}

/* SPH / WCSPH: pressure from density. */
static void ph_pressure(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const ak_fluid_desc* d = &c->d;
    if (d->solver == AK_FLUID_SPH) {
        for (size_t i = b; i < e; ++i) c->pres[i] = d->stiffness * (c->rho[i] - c->rho0);
    } else {
        const float B = c->rho0 * d->sound_speed * d->sound_speed / d->tait_gamma;
        for (size_t i = b; i < e; ++i) c->pres[i] = B * (powf(c->rho[i] / c->rho0, d->tait_gamma) - 1.0f);
    }
}

/* SIMD SPH / WCSPH: (v, rho) records into q4 and the pressures into p4's w, for the force
 * kernels (p4 is rebuilt by the next step's sort; no other pass reads its w). */
static void ph_pack_forces(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t i = b; i < e; ++i) {
        c->q4[4 * i] = c->v[i].x, c->q4[4 * i + 1] = c->v[i].y, c->q4[4 * i + 2] = c->v[i].z, c->q4[4 * i + 3] = c->rho[i];
        c->p4[4 * i + 3] = c->pres[i];
    }
}

/* SPH / WCSPH: accelerations into acc. */
static void ph_forces(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    if (c->simd) {
        (c->kernels == AK_FLUID_KERNELS_AVX512 ? akp_fluid_forces_avx512 : akp_fluid_forces_avx2)(c, b, e);
        return;
    }
    const ak_fluid_desc* d = &c->d;
    const bool mcg = d->solver == AK_FLUID_SPH;
    const float mu = d->viscosity, m = c->m, h = c->h;
    for (size_t i = b; i < e; ++i) {
        const uint32_t* nb = akp_fluid_nb(c, i);
        const ak_vec3 pi = P(c, (uint32_t)i), vi = c->v[i];
        const float rhoi = c->rho[i], pri = c->pres[i];
        ak_vec3 a = {0.0f, 0.0f, 0.0f};
        for (uint32_t q = 0; q < c->nb_count[i]; ++q) {
            const uint32_t j = nb[(size_t)q * 16];
            if (j == i) continue;
            ak_vec3 r = ak_vec3_sub(pi, P(c, j));
            ak_vec3 g = mcg ? k_spiky(c, r) : k_cubic_grad(c, r);
            const float rhoj = c->rho[j];
            if (mcg) {
                /* f_i = -sum m (p_i + p_j) / (2 rho_j) grad W + mu sum m v_ij / rho_j lap W; a = f / rho_i */
                a = ak_vec3_add(a, ak_vec3_scale(g, -m * (pri + c->pres[j]) / (2.0f * rhoj)));
                if (mu != 0.0f)
                    a = ak_vec3_add(a, ak_vec3_scale(ak_vec3_sub(c->v[j], vi),
                                                     mu * m / rhoj * ak_fluid_visc_laplacian(ak_vec3_length(r), h)));
            } else {
                float coef = pri / (rhoi * rhoi) + c->pres[j] / (rhoj * rhoj);
                if (mu != 0.0f) {
                    ak_vec3 vij = ak_vec3_sub(vi, c->v[j]);
                    float vx = ak_vec3_dot(vij, r);
                    if (vx < 0.0f) {
                        float nu = 2.0f * mu * h * d->sound_speed / (rhoi + rhoj);
                        coef += -nu * vx / (ak_vec3_dot(r, r) + 0.01f * h * h);
                    }
                }
                a = ak_vec3_add(a, ak_vec3_scale(g, -m * coef));
            }
        }
        akp_fluid_forces_finish(c, i, a);
    }
}

void akp_fluid_forces_finish(akp_fluid_ctx* c, size_t i, ak_vec3 a) {
    if (c->d.solver == AK_FLUID_SPH) a = ak_vec3_scale(a, 1.0f / c->rho[i]);
    c->acc[i] = ak_vec3_add(a, c->d.gravity);
}

/* SPH / WCSPH: semi-implicit Euler into q (positions) and v. */
static void ph_integrate(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t i = b; i < e; ++i) {
        ak_vec3 v = ak_vec3_add(c->v[i], ak_vec3_scale(c->acc[i], c->dt));
        ak_vec3 p = ak_vec3_add(P(c, (uint32_t)i), ak_vec3_scale(v, c->dt));
        akp_fluid_collide(c, &p, &v);
        c->qx[i] = p.x, c->qy[i] = p.y, c->qz[i] = p.z;
        c->v[i] = v;
    }
}

static void ph_flags(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const uint32_t surf = (c->full_lattice_count * 3u) / 4u;
    for (size_t i = b; i < e; ++i) {
        uint8_t f = 0;
        if (c->nb_count[i] < surf) f |= AK_FLUID_FLAG_SURFACE;
        else if (boundary_distance(c, P(c, (uint32_t)i)) >= c->h) f |= AK_FLUID_FLAG_FULL;
        c->flags[i] = f;
    }
}

/* A full neighbourhood also needs every neighbour away from the free surface. */
static void ph_full(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    for (size_t i = b; i < e; ++i) {
        if (!(c->flags[i] & AK_FLUID_FLAG_FULL)) continue;
        const uint32_t* nb = akp_fluid_nb(c, i);
        bool full = true;
        for (uint32_t q = 0; q < c->nb_count[i] && full; ++q) full = !(c->flags[nb[(size_t)q * 16]] & AK_FLUID_FLAG_SURFACE);
        c->lambda[i] = full ? 1.0f : 0.0f;
    }
    /* the flags of [b, e) are dropped by ph_scatter: other threads still read them here */
}

/* Final positions (PBF: p; SPH: q), velocities, densities, pressures, flags back to the
 * caller's order. */
static void ph_scatter(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const ak_fluid_step_job* job = c->job;
    const bool pbf = c->d.solver == AK_FLUID_PBF;
    const float *fx = pbf ? c->px : c->qx, *fy = pbf ? c->py : c->qy, *fz = pbf ? c->pz : c->qz;
    for (size_t a = b; a < e; ++a) {
        const uint32_t i = c->order[a];
        if ((c->flags[a] & AK_FLUID_FLAG_FULL) && c->lambda[a] == 0.0f) c->flags[a] = 0; /* see ph_full */
        c->xo[i] = ak_vec3_make(fx[a], fy[a], fz[a]);
        c->vo[i] = c->v[a];
        if (job->out_densities.ptr) job->out_densities.ptr[i] = c->rho[a];
        if (job->out_pressures.ptr) job->out_pressures.ptr[i] = c->pres[a];
        if (job->out_flags.ptr) job->out_flags.ptr[i] = c->flags[a];
    }
}

/* The statistics of sorted particles [k STATS_CHUNK, (k + 1) STATS_CHUNK) for chunks k in
 * [b, e) (see the end of ak_fluid_step_run). */
static void ph_stats(ctx* c, size_t b, size_t e, uint32_t t) {
    (void)t;
    const float limit = 100.0f * c->h;
    for (size_t k = b; k < e; ++k) {
        stats_part q = {0};
        const size_t a1 = (k + 1) * STATS_CHUNK < c->n ? (k + 1) * STATS_CHUNK : c->n;
        for (size_t a = k * STATS_CHUNK; a < a1; ++a) {
            const uint32_t i = c->order[a];
            const ak_vec3 v = c->vo[i];
            if (!vfinite(c->xo[i]) || !vfinite(v) || !(ak_vec3_length(v) * c->dt <= limit)) q.blown = true;
            if (c->flags[a] & AK_FLUID_FLAG_SURFACE) ++q.surface;
            if (c->flags[a] & AK_FLUID_FLAG_FULL) {
                float err = fabsf(c->rho[a] / c->rho0 - 1.0f);
                if (err > q.max_err) q.max_err = err;
                q.sum_err += err;
                q.sum_rho += c->rho[a];
                ++q.full;
            }
        }
        c->stats[k] = q;
    }
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Emitters: layer k of an emitter leaves the nozzle at start + k * s / speed; every layer due
 * in [time, time + dt) is added, advanced along the flow by the time left in the step. */
static void emit(const ak_fluid_step_job* job, float s, size_t* n, ak_fluid_stats* st) {
    const size_t cap = job->positions.count;
    const float t0 = job->time, t1 = job->time + job->dt;
    for (size_t e = 0; e < job->emitters.count; ++e) {
        const ak_fluid_emitter* em = &job->emitters.ptr[e];
        ak_vec3 dir = ak_vec3_length_sq(em->direction) > 0.0f ? ak_vec3_normalize(em->direction)
                                                               : ak_vec3_make(0.0f, -1.0f, 0.0f);
        /* an orthonormal basis of the nozzle plane */
        ak_vec3 helper = fabsf(dir.y) < 0.9f ? ak_vec3_make(0, 1, 0) : ak_vec3_make(1, 0, 0);
        ak_vec3 u = ak_vec3_normalize(ak_vec3_cross(helper, dir));
        ak_vec3 w = ak_vec3_cross(dir, u);
        const double period = (double)s / em->speed;
        double kf = ceil(((double)t0 - em->start_time) / period);
        if (kf < 0.0) kf = 0.0;
        const int ring = (int)floorf(em->radius / s);
        for (int guard = 0; guard < 100000; ++guard, kf += 1.0) {
            const double te = em->start_time + kf * period;
            if (te >= t1) break;
            if (te < t0) continue;
            if (em->stop_time > 0.0f && te >= em->stop_time) break;
            const float ahead = (float)((t1 - te) * em->speed);
            const float r2 = em->radius * em->radius + 1e-6f * s * s;
            for (int a = -ring; a <= ring; ++a) {
                const float fa = (float)a * s;
                if (fa * fa > r2) continue;
                if (*n >= cap) { /* full: count this row's lattice points without visiting them */
                    const double bmax = floor(sqrt(fmax(0.0, (double)r2 - (double)fa * fa)) / s);
                    if (st) st->emit_dropped_count += (size_t)(2.0 * bmax + 1.0);
                    continue;
                }
                for (int bq = -ring; bq <= ring; ++bq) {
                    const float fb = (float)bq * s;
                    if (fa * fa + fb * fb > r2) continue;
                    if (*n >= cap) {
                        if (st) ++st->emit_dropped_count;
                        continue;
                    }
                    ak_vec3 p = ak_vec3_add(em->position,
                                            ak_vec3_add(ak_vec3_add(ak_vec3_scale(u, fa), ak_vec3_scale(w, fb)),
                                                        ak_vec3_scale(dir, ahead)));
                    job->positions.ptr[*n] = p;
                    job->velocities.ptr[*n] = ak_vec3_scale(dir, em->speed);
                    ++*n;
                    if (st) ++st->emitted_count;
                }
            }
        }
    }
}


ak_result ak_fluid_step_run(const ak_fluid_step_job* job) {
    ak_result r = validate(job, false);
    if (r != AK_OK) return r;
    {
        /* the particles' data, split over the threads (one read of 24 bytes a particle: half a
         * millisecond for 500,000 on one core, all of it serial before) */
        int res[AKP_TASKS_MAX];
        const uint32_t parts = akp_check_split(*job->particle_count, job->thread_count, scan_particles_part, job, res);
        for (uint32_t t = 0; t < parts; ++t)
            if (res[t] != (int)AK_OK) return AK_ERR_BAD_DATA;
    }
    ctx cstore;
    ctx* c = &cstore;
    memset(c, 0, sizeof *c);
    c->d = ak_fluid_desc_resolved(job->desc);
    c->job = job;
    c->dt = job->dt;
    c->h = c->d.h;
    c->h2 = c->h * c->h;
    c->rho0 = c->d.rest_density;
    c->m = c->d.particle_mass;
    c->mr = c->m / c->rho0;
    c->K = c->d.max_neighbours;
    c->inv_cell = 1.0 / (double)c->h;
    c->kernels = ak_fluid_kernels_resolved(job->kernels);
    c->simd = c->kernels != AK_FLUID_KERNELS_SCALAR;
    const float s = cbrtf(c->mr);
    float wsum;
    lattice_props(c->h, s, c->mr, &c->full_lattice_count, &c->grad2_rest, &wsum);
    c->rho_c = c->m * wsum;
    c->coincident2 = 1e-4f * s * s; /* (1% of the rest spacing)^2 */
    {
        const float h2 = c->h * c->h, h3 = h2 * c->h;
        c->poly6_k = (float)(315.0 / (64.0 * FLUID_PI)) / (h2 * h2 * h2 * h2 * c->h);
        c->spiky_k = -(float)(45.0 / FLUID_PI) / (h3 * h3);
        c->inv_h = 1.0f / c->h;
        c->cubic_k = (float)(8.0 / FLUID_PI) / h3;
        c->cubic_gk = (float)(48.0 / FLUID_PI) / (h3 * c->h);
        c->visc_lap_k = (float)(45.0 / FLUID_PI) / (h3 * h3); /* ak_fluid_visc_laplacian's factor */
    }
    c->wdq = ak_fluid_poly6(c->d.scorr_dq * c->h * c->d.scorr_dq * c->h, c->h);

    ak_fluid_stats st;
    memset(&st, 0, sizeof st);
    const size_t cap = job->positions.count;
    layout L;
    memset(&L, 0, sizeof L);
    if (!make_layout(cap, &c->d, &L)) return AK_ERR_BAD_ARG;
    uint8_t* base = job->scratch.ptr;
    base += (64u - ((uintptr_t)base & 63u)) & 63u;
#define AT(type, field) ((type*)(void*)(base + L.field))
    c->dstart = AT(uint32_t, dstart);
    c->nb_count = AT(uint32_t, nb_count);
    c->nb = AT(uint32_t, nb);
    c->tbuf = AT(uint32_t, tbuf);
    c->order = AT(uint32_t, order);
    c->cell = AT(uint32_t, cell);
    c->pred = AT(ak_vec3, pred);
    c->px = AT(float, px), c->py = AT(float, py), c->pz = AT(float, pz);
    c->qx = AT(float, qx), c->qy = AT(float, qy), c->qz = AT(float, qz);
    c->p4 = AT(float, p4), c->q4 = AT(float, q4);
    c->x0 = AT(ak_vec3, x0);
    c->v = AT(ak_vec3, v);
    c->acc = AT(ak_vec3, acc);
    c->omega = AT(ak_vec3, omega);
    c->omega_len = AT(float, omega_len);
    c->vnew = AT(ak_vec3, vnew);
    c->lambda = AT(float, lambda);
    c->rho = AT(float, rho);
    c->pres = AT(float, pres);
    c->flags = AT(uint8_t, flags);
#undef AT
    c->xo = job->positions.ptr;
    c->vo = job->velocities.ptr;

    size_t n = *job->particle_count;
    emit(job, s, &n, &st);
    c->n = n;
    const uint32_t threads = job->thread_count ? job->thread_count : 1;
    const bool pbf = c->d.solver == AK_FLUID_PBF;

    team tm;
    worker ws[AKP_FLUID_MAX_THREADS];
    team_start(c, &tm, ws, n >= 1024 ? threads : 1u); /* small steps: the caller alone */

    /* predict (PBF) or take the current positions (SPH), sort by cell, neighbour lists */
    parallel(c, ph_predict);
    const double t_nb = now_seconds();
    ak_grid_desc gd = {.cell_size = c->h};
    bool dense = false;
    if (!sort_by_cell(c, base + L.grid, ak_grid_memory_size(n, &gd), cap, &dense)) {
        team_stop(c);
        return AK_ERR_NO_CONVERGENCE; /* only non-finite predictions fail here */
    }
    if (dense) parallel(c, ph_neighbours_dense);
    else parallel_n(c, ph_neighbours_hashed, c->grid.cell_count);
    if (c->simd) parallel(c, ph_pad_lists);
    st.neighbour_seconds = (float)(now_seconds() - t_nb);
    parallel(c, ph_gather);

    if (pbf) {
        for (uint32_t it = 0; it < c->d.iterations; ++it) {
            parallel(c, ph_lambda);
            parallel(c, ph_delta);
            float* tmp;
            tmp = c->px, c->px = c->qx, c->qx = tmp;
            tmp = c->py, c->py = c->qy, c->qy = tmp;
            tmp = c->pz, c->pz = c->qz, c->qz = tmp;
        }
        parallel(c, ph_velocity);
        parallel(c, ph_density);
        if (c->simd && (c->d.vorticity_epsilon != 0.0f || c->d.xsph_c != 0.0f)) parallel(c, ph_pack_v);
        if (c->d.vorticity_epsilon != 0.0f) parallel(c, ph_vorticity);
        if (c->d.vorticity_epsilon != 0.0f || c->d.xsph_c != 0.0f) {
            parallel(c, ph_xsph);
            ak_vec3* t = c->v; /* the smoothed velocities are the step's */
            c->v = c->vnew, c->vnew = t;
        }
    } else {
        parallel(c, ph_density);
        parallel(c, ph_pressure);
        if (c->simd) parallel(c, ph_pack_forces);
        parallel(c, ph_forces);
        parallel(c, ph_integrate);
    }
    parallel(c, ph_flags);
    parallel(c, ph_full);
    parallel(c, ph_scatter);
    /* blow-up check, statistics: per chunk of STATS_CHUNK sorted particles over the team, the
     * chunks then summed in order (the same sums for any thread count). The chunks' partials
     * live in acc, free by now (or on the stack for small steps). */
    const size_t chunks = (n + STATS_CHUNK - 1) / STATS_CHUNK;
    stats_part small[8];
    c->stats = chunks <= 8 ? small : (stats_part*)(void*)c->acc;
    parallel_n(c, ph_stats, chunks);
    team_stop(c);
    bool blown = false;
    double sum = 0.0, sum_rho = 0.0;
    for (size_t k = 0; k < chunks; ++k) {
        const stats_part* q = &c->stats[k];
        blown = blown || q->blown;
        st.surface_count += q->surface;
        st.full_count += q->full;
        if (q->max_err > st.max_density_error) st.max_density_error = q->max_err;
        sum += q->sum_err;
        sum_rho += q->sum_rho;
    }
    c->stats = NULL;
    st.mean_density_error = st.full_count ? (float)(sum / (double)st.full_count) : 0.0f;
    st.mean_density = st.full_count ? (float)(sum_rho / (double)st.full_count) : 0.0f;
    st.rest_lattice_density = c->rho_c;
    for (uint32_t t = 0; t < AKP_FLUID_MAX_THREADS; ++t) {
        st.truncated_count += c->truncated[t];
        st.coincident_count += c->coincident[t];
    }

    /* sinks: stable compaction (order of the survivors kept) */
    if (job->sinks.count) {
        size_t w = 0;
        for (size_t i = 0; i < n; ++i) {
            ak_vec3 p = c->xo[i];
            bool gone = false;
            for (size_t k = 0; k < job->sinks.count && !gone; ++k) {
                const ak_fluid_sink* sk = &job->sinks.ptr[k];
                gone = p.x >= sk->min.x && p.x <= sk->max.x && p.y >= sk->min.y && p.y <= sk->max.y &&
                       p.z >= sk->min.z && p.z <= sk->max.z;
            }
            if (gone) {
                ++st.removed_count;
                continue;
            }
            if (w != i) {
                c->xo[w] = c->xo[i];
                c->vo[w] = c->vo[i];
                if (job->out_densities.ptr) job->out_densities.ptr[w] = job->out_densities.ptr[i];
                if (job->out_pressures.ptr) job->out_pressures.ptr[w] = job->out_pressures.ptr[i];
                if (job->out_flags.ptr) job->out_flags.ptr[w] = job->out_flags.ptr[i];
            }
            ++w;
        }
        n = w;
    }
    *job->particle_count = n;
    if (job->out_stats) *job->out_stats = st;
    return blown ? AK_ERR_NO_CONVERGENCE : AK_OK;
}
