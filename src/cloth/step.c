/* Cloth step: XPBD, PBD and mass-spring solvers, wind, collisions, threads.
 *
 * Threads run the whole step together (SPMD): every phase splits its elements (particles,
 * triangles, or the constraints of one colour) into thread_count contiguous ranges and the
 * threads meet at a barrier between phases. Every element is computed the same way whatever
 * range it falls in, and no two threads write the same particle within a phase, so the result
 * does not depend on the thread count. The XPBD/PBD constraint solves are cloth_kernel.h's,
 * here in their scalar variant and in cloth_avx2.c / cloth_avx512.c in SIMD ones (chosen at run
 * time; the same bits). The step works on a copy of the positions as 16-byte (position, inverse
 * mass) records, copied back at the end. */
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>

#include <animkit/grid.h>

#include "cloth_impl.h"
#include "internal.h"
#include "tasks.h"

#define MAX_THREADS 64u
/* Threads meet at a barrier after every constraint colour (25 meetings per substep of a grid
 * with dihedral bending: 8 distance and 16 bending colours, both the fewest possible on the grid
 * (cloth.c), and the collisions fused with the next prediction). With the SIMD solves a constraint costs 2-5 ns, so a thread's
 * share of a colour must be thousands of constraints to outweigh a meeting (about a microsecond
 * between two running threads, a scheduler time slice when the partner was descheduled): XPBD
 * and PBD use at most one thread per this many constraints of an average colour, unless the job
 * asks for exact_thread_count. 1024 (was 8192, which held a 256^2 grid to 4 threads and a 512^2
 * one to 16 of 64): a share of 1024 constraints is 2-5 us of work against a ~1 us meeting, and
 * the per-phase CPU profile (bench_scaling --cpu) predicts 16 threads on 256^2 at about half
 * the efficiency of 512^2 rather than a quarter (docs/BENCHMARKS.md, issue 35). */
#define THREAD_MIN_PER_COLOR 1024u

/* ---- scratch layout --------------------------------------------------------------------- */

/* IMPLICIT: the conjugate-gradient vectors (3 n doubles each) */
enum { CG_DV, CG_R, CG_C, CG_Q, CG_S, CG_B, CG_PRE, CG_VECTORS };

typedef struct layout {
    size_t xw, xs, prev, ext, acc, lambda, tri_force, off, hash_start, hash_entry, tri_normal, grid, grid_size, size;
    size_t dist_stride, bend_stride; /* bytes between the per-step offset arrays */
    size_t cg;                       /* IMPLICIT: CG_VECTORS vectors of 3 n doubles, then 4 per spring */
    size_t buckets, mesh_tris;
} layout;

static size_t pow2_at_least(size_t x) {
    size_t p = 1;
    while (p < x) p <<= 1;
    return p;
}

static float self_distance(const ak_cloth_step_job* job) {
    const float th = job->thickness > 0.0f ? job->thickness : 0.01f;
    return job->self_distance > 0.0f ? job->self_distance : 2.0f * th;
}

static layout make_layout(const ak_cloth* c, size_t mesh_tris, const ak_cloth_step_job* job) {
    layout l;
    size_t s = 0;
    l.xw = s, s += akp_align16(c->n * sizeof(akp_px));
    l.xs = s, s += job->self_collision ? akp_align16(c->n * sizeof(ak_vec3)) : 0;
    l.prev = s, s += akp_align16(c->n * sizeof(akp_px));
    l.ext = s, s += akp_align16(c->n * sizeof(ak_vec3));
    l.acc = s, s += akp_align16(c->n * sizeof(ak_vec3));
    l.lambda = s, s += akp_align16((c->dist_count + c->bend_count) * sizeof(float));
    l.tri_force = s, s += akp_align16(c->tri_count * sizeof(ak_vec3));
    l.dist_stride = akp_align16(c->dist_count * sizeof(float));
    l.bend_stride = akp_align16(c->bend_count * sizeof(float));
    l.off = s, s += akp_spring_solver(c->desc.solver)
                        ? 0
                        : 3 * l.dist_stride + (c->desc.bending == AK_CLOTH_BEND_ISOMETRIC ? 3 : 9) * l.bend_stride;
    l.cg = s, s += c->desc.solver == AK_CLOTH_IMPLICIT ? akp_align16((CG_VECTORS * 3 * c->n + 4 * c->dist_count) * sizeof(double)) : 0;
    l.mesh_tris = mesh_tris;
    l.buckets = mesh_tris ? pow2_at_least(2 * mesh_tris) : 0;
    l.hash_start = s, s += akp_align16(mesh_tris ? (l.buckets + 1) * sizeof(uint32_t) : 0);
    l.hash_entry = s, s += akp_align16(mesh_tris * 8 * sizeof(uint32_t));
    l.tri_normal = s, s += akp_align16(mesh_tris * sizeof(ak_vec3));
    l.grid_size = 0;
    if (job->self_collision) {
        const ak_grid_desc gd = {.cell_size = self_distance(job)};
        l.grid_size = ak_grid_memory_size(c->n, &gd);
    }
    l.grid = s, s += akp_align16(l.grid_size);
    l.size = s + 16; /* room to align the caller's pointer */
    return l;
}

size_t ak_cloth_step_scratch_size(const ak_cloth_step_job* job) {
    if (!job || !job->cloth) return 0;
    return make_layout(job->cloth, job->mesh.indices.count / 3, job).size;
}

/* ---- validation ------------------------------------------------------------------------- */

static bool bad_nonneg(float x) { return !(x >= 0.0f) || !ak_finitef(x); }

/* A vertex's caller data are finite (positions, velocities, residuals when kept). */
static bool vertex_finite(const ak_cloth_step_job* job, size_t v) {
    return ak_vec3_is_finite(job->positions.ptr[v]) && ak_vec3_is_finite(job->velocities.ptr[v]) &&
           (!job->position_residuals.ptr || ak_vec3_is_finite(job->position_residuals.ptr[v]));
}

/* The checks of ak_cloth_step_validate; scan_vertices false leaves out the O(n) check of the
 * vertices' data (vertex_finite), which ak_cloth_step_run does on its threads instead. */
static ak_result validate(const ak_cloth_step_job* job, bool scan_vertices) {
    if (!job || !job->cloth || !job->positions.ptr || !job->velocities.ptr || !job->scratch.ptr) return AK_ERR_NULL_ARG;
    const ak_cloth* c = job->cloth;
    if ((job->plane_count && !job->planes) || (job->sphere_count && !job->spheres) ||
        (job->capsule_count && !job->capsules) || (c->attach_count && !job->attachment_targets.ptr) ||
        (job->mesh.indices.count && !job->mesh.positions.ptr) || (job->mesh.positions.count && !job->mesh.indices.ptr))
        return AK_ERR_NULL_ARG;
    if (!(job->dt > 0.0f) || !ak_finitef(job->dt) || job->thread_count > MAX_THREADS || job->substeps > 10000 ||
        job->iterations > 10000 || (unsigned)job->simd_limit >= AK_CLOTH_SIMD_COUNT)
        return AK_ERR_BAD_ARG;
    if (bad_nonneg(job->drag) || bad_nonneg(job->lift) || bad_nonneg(job->air_density) || bad_nonneg(job->damping) ||
        bad_nonneg(job->thickness) || bad_nonneg(job->friction) || bad_nonneg(job->self_distance))
        return AK_ERR_BAD_ARG;
    if (job->mesh.indices.count % 3 || job->positions.count != c->n || job->velocities.count != c->n ||
        job->attachment_targets.count != c->attach_count ||
        (job->position_residuals.ptr && job->position_residuals.count != c->n))
        return AK_ERR_BAD_ARG;
    for (size_t k = 0; k < job->sphere_count; ++k)
        if (job->spheres[k].radius < 0.0f) return AK_ERR_BAD_ARG;
    for (size_t k = 0; k < job->capsule_count; ++k)
        if (job->capsules[k].radius < 0.0f) return AK_ERR_BAD_ARG;
    if (job->out_normals.ptr && job->out_normals.count < c->n) return AK_ERR_SPAN_SMALL;
    if (job->scratch.count < ak_cloth_step_scratch_size(job)) return AK_ERR_SPAN_SMALL;
    for (size_t k = 0; k < job->mesh.indices.count; ++k)
        if (job->mesh.indices.ptr[k] >= job->mesh.positions.count) return AK_ERR_BAD_INDEX;
    /* data */
    if (!ak_vec3_is_finite(job->gravity) || !ak_vec3_is_finite(job->wind)) return AK_ERR_BAD_DATA;
    for (size_t v = 0; scan_vertices && v < c->n; ++v)
        if (!vertex_finite(job, v)) return AK_ERR_BAD_DATA;
    for (size_t k = 0; k < job->plane_count; ++k)
        if (!ak_vec3_is_finite(job->planes[k].normal) || !ak_finitef(job->planes[k].offset)) return AK_ERR_BAD_DATA;
    for (size_t k = 0; k < job->sphere_count; ++k)
        if (!ak_vec3_is_finite(job->spheres[k].center) || !ak_finitef(job->spheres[k].radius)) return AK_ERR_BAD_DATA;
    for (size_t k = 0; k < job->capsule_count; ++k)
        if (!ak_vec3_is_finite(job->capsules[k].a) || !ak_vec3_is_finite(job->capsules[k].b) ||
            !ak_finitef(job->capsules[k].radius))
            return AK_ERR_BAD_DATA;
    for (size_t k = 0; k < job->mesh.positions.count; ++k)
        if (!ak_vec3_is_finite(job->mesh.positions.ptr[k])) return AK_ERR_BAD_DATA;
    for (size_t k = 0; k < job->attachment_targets.count; ++k)
        if (!ak_vec3_is_finite(job->attachment_targets.ptr[k])) return AK_ERR_BAD_DATA;
    return AK_OK;
}

ak_result ak_cloth_step_validate(const ak_cloth_step_job* job) { return validate(job, true); }

/* ---- the shared step context ------------------------------------------------------------ */

typedef struct ctx {
    const ak_cloth_step_job* job;
    const ak_cloth* c;
    unsigned T;          /* threads taking part */
    uint32_t substeps, iterations;
    float h, decay, thickness;
    const ak_vec3* base; /* the caller's positions: where the step starts */
    akp_px* x;       /* working copy: displacements from base, with inverse masses */
    ak_vec3* xs;     /* plain copy for the self-collision grid */
    ak_vec3* v;
    akp_px* prev;
    ak_vec3* ext;
    ak_vec3* acc;
    float* lambda;
    ak_vec3* tri_force;
    /* mesh collider hash */
    uint32_t* hash_start;
    uint32_t* hash_entry;
    ak_vec3* tri_normal;
    size_t buckets;
    float cell;
    /* self-collision */
    bool self;
    float self_dist;
    ak_u8_span grid_mem;
    ak_grid grid;
    ak_result grid_result;
    akp_solve solve;
    double* cg;          /* IMPLICIT: the CG vectors, then per spring u (3) and its clamped
                            transverse factor (1; -1: degenerate) */
    uint32_t cg_max;     /* IMPLICIT: most CG iterations per substep */
    int simd;            /* 0 scalar, 1 AVX2, 2 AVX-512 */
    _Alignas(64) akp_barrier bar; /* the step's team meets here between phases (src/tasks.h): on
                                     cache lines of its own, as every thread writes it at every
                                     meeting and the fields above are read all the time */
    char bar_pad[64];             /* nothing after it on its last line */
    bool finite[MAX_THREADS]; /* per thread: its vertices ended finite */
    bool bad[MAX_THREADS];    /* per thread: one of its vertices came in non-finite */
} ctx;

typedef struct worker {
    ctx* c;
    unsigned t;
} worker;

static void barrier(ctx* c) {
    if (c->T > 1) akp_barrier_wait(&c->bar);
}

static void range(size_t count, unsigned t, unsigned T, size_t* b, size_t* e) {
    *b = count * t / T;
    *e = count * (t + 1) / T;
}

/* range() with the inner boundaries on multiples of 16, so that each thread's share of a
 * colour is whole SIMD blocks but for the last one's tail. */
static void block_range(size_t count, unsigned t, unsigned T, size_t* b, size_t* e) {
    const size_t blocks = (count + 15) / 16;
    *b = t == 0 ? 0 : blocks * t / T * 16;
    *e = t + 1 == T ? count : blocks * (t + 1) / T * 16;
    if (*b > count) *b = count;
    if (*e > count) *e = count;
}

/* Thread t's share [*kb, *ke) of colour col of a constraint list whose colours start at
 * starts[0..AKP_MAX_COLORS + 1]: the serial colour all on thread 0, the others in blocks of 16
 * (block_range). False when the colour is empty (every thread skips it, barrier included). */
static bool color_share(const uint32_t* starts, int col, unsigned t, unsigned T, size_t* kb, size_t* ke) {
    const size_t cb = starts[col], ce = starts[col + 1];
    if (cb == ce) return false;
    if (col == AKP_SERIAL_COLOR) {
        *kb = t == 0 ? cb : ce, *ke = ce;
    } else {
        block_range(ce - cb, t, T, kb, ke);
        *kb += cb, *ke += cb;
    }
    return true;
}

/* ---- positions ---------------------------------------------------------------------------- */

/* x_i - x_j now: the difference at the start of the step (exact for nearby floats) plus the
 * difference of the displacements, so it keeps its relative precision far from the origin. */
static ak_vec3 rel(const ctx* c, size_t i, size_t j) {
    return ak_vec3_add(ak_vec3_sub(c->base[i], c->base[j]), ak_vec3_sub(c->x[i].p, c->x[j].p));
}

/* World position of particle v now (rounded to float: for colliders and the neighbour grid). */
static ak_vec3 world(const ctx* c, size_t v) { return ak_vec3_add(c->base[v], c->x[v].p); }

/* ---- collisions ------------------------------------------------------------------------- */

static uint32_t hash_cell(int32_t x, int32_t y, int32_t z, size_t buckets) {
    const uint32_t h = ((uint32_t)x * 73856093u) ^ ((uint32_t)y * 19349663u) ^ ((uint32_t)z * 83492791u);
    return h & (uint32_t)(buckets - 1);
}

static int32_t cell_of(float x, float cell) {
    float q = floorf(x / cell);
    if (q > 1e9f) q = 1e9f;
    if (q < -1e9f) q = -1e9f;
    return (int32_t)q;
}

/* Spatial hash of the collider's triangles (Teschner et al. 2003), each inserted in every cell
 * its box (grown by the detection distance) overlaps: at most 8, as a cell is as large as the
 * largest grown box. Counting sort into hash_start/hash_entry. */
static void build_hash(ctx* c, float reach) {
    const ak_cloth_collider_mesh* m = &c->job->mesh;
    const size_t nt = m->indices.count / 3;
    float cell = 0.0f;
    for (size_t t = 0; t < nt; ++t) {
        const ak_vec3 a = m->positions.ptr[m->indices.ptr[3 * t]], b = m->positions.ptr[m->indices.ptr[3 * t + 1]],
                      d = m->positions.ptr[m->indices.ptr[3 * t + 2]];
        const ak_vec3 lo = ak_vec3_min(a, ak_vec3_min(b, d)), hi = ak_vec3_max(a, ak_vec3_max(b, d));
        cell = ak_maxf(cell, ak_maxf(hi.x - lo.x, ak_maxf(hi.y - lo.y, hi.z - lo.z)) + 2.0f * reach);
        c->tri_normal[t] = ak_vec3_normalize(ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(d, a)));
    }
    c->cell = cell > 1e-6f ? cell : 1e-6f;
    memset(c->hash_start, 0, (c->buckets + 1) * sizeof(uint32_t));
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t t = 0; t < nt; ++t) {
            const ak_vec3 a = m->positions.ptr[m->indices.ptr[3 * t]], b = m->positions.ptr[m->indices.ptr[3 * t + 1]],
                          d = m->positions.ptr[m->indices.ptr[3 * t + 2]];
            const ak_vec3 r = ak_vec3_make(reach, reach, reach);
            const ak_vec3 lo = ak_vec3_sub(ak_vec3_min(a, ak_vec3_min(b, d)), r);
            const ak_vec3 hi = ak_vec3_add(ak_vec3_max(a, ak_vec3_max(b, d)), r);
            const int32_t x0 = cell_of(lo.x, c->cell), x1 = cell_of(hi.x, c->cell), y0 = cell_of(lo.y, c->cell),
                          y1 = cell_of(hi.y, c->cell), z0 = cell_of(lo.z, c->cell), z1 = cell_of(hi.z, c->cell);
            uint32_t seen[8];
            int ns = 0;
            for (int32_t x = x0; x <= x1 && x <= x0 + 1; ++x)
                for (int32_t y = y0; y <= y1 && y <= y0 + 1; ++y)
                    for (int32_t z = z0; z <= z1 && z <= z0 + 1; ++z) {
                        const uint32_t h = hash_cell(x, y, z, c->buckets);
                        bool dup = false;
                        for (int q = 0; q < ns; ++q) dup = dup || seen[q] == h;
                        if (dup) continue;
                        seen[ns++] = h;
                        if (pass == 0) c->hash_start[h + 1]++;
                        else c->hash_entry[c->hash_start[h]++] = (uint32_t)t;
                    }
        }
        if (pass == 0)
            for (size_t k = 0; k < c->buckets; ++k) c->hash_start[k + 1] += c->hash_start[k];
    }
    /* pass 1 advanced each start to its end: shift back */
    for (size_t k = c->buckets; k > 0; --k) c->hash_start[k] = c->hash_start[k - 1];
    c->hash_start[0] = 0;
}

/* Closest point to p on triangle abc (Ericson, Real-Time Collision Detection, 5.1.5). */
static ak_vec3 closest_on_triangle(ak_vec3 p, ak_vec3 a, ak_vec3 b, ak_vec3 c) {
    const ak_vec3 ab = ak_vec3_sub(b, a), ac = ak_vec3_sub(c, a), ap = ak_vec3_sub(p, a);
    const float d1 = ak_vec3_dot(ab, ap), d2 = ak_vec3_dot(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f) return a;
    const ak_vec3 bp = ak_vec3_sub(p, b);
    const float d3 = ak_vec3_dot(ab, bp), d4 = ak_vec3_dot(ac, bp);
    if (d3 >= 0.0f && d4 <= d3) return b;
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return ak_vec3_madd(a, ab, d1 / (d1 - d3));
    const ak_vec3 cp = ak_vec3_sub(p, c);
    const float d5 = ak_vec3_dot(ab, cp), d6 = ak_vec3_dot(ac, cp);
    if (d6 >= 0.0f && d5 <= d6) return c;
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return ak_vec3_madd(a, ac, d2 / (d2 - d6));
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
        return ak_vec3_madd(b, ak_vec3_sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const float denom = 1.0f / (va + vb + vc);
    return ak_vec3_add(a, ak_vec3_add(ak_vec3_scale(ab, vb * denom), ak_vec3_scale(ac, vc * denom)));
}

/* Friction at a contact of normal n and penetration depth: the tangential motion of this
 * substep shrinks by up to friction * depth (position-level Coulomb friction). */
static ak_vec3 apply_friction(ak_vec3 x, ak_vec3 prev, ak_vec3 n, float depth, float mu) {
    if (mu <= 0.0f) return x;
    const ak_vec3 d = ak_vec3_sub(x, prev);
    const ak_vec3 t = ak_vec3_madd(d, n, -ak_vec3_dot(d, n));
    const float lt = ak_vec3_length(t);
    if (lt <= 1e-12f) return x;
    return ak_vec3_madd(x, t, -ak_minf(1.0f, mu * depth / lt));
}

/* Push a point out of a sphere of radius r around center. */
static bool push_sphere(ak_vec3* x, ak_vec3 center, float r, ak_vec3* n, float* depth) {
    const ak_vec3 d = ak_vec3_sub(*x, center);
    const float l2 = ak_vec3_length_sq(d);
    if (l2 >= r * r) return false;
    const float l = sqrtf(l2);
    *n = l > 1e-12f ? ak_vec3_scale(d, 1.0f / l) : ak_vec3_make(0, 1, 0);
    *depth = r - l;
    *x = ak_vec3_madd(center, *n, r);
    return true;
}

/* Push particle i out of the colliders; true when it moved (its displacement is then rewritten
 * from the world position; otherwise it is left as it was). */
static bool collide(const ctx* c, size_t i) {
    const ak_cloth_step_job* job = c->job;
    const float th = c->thickness, mu = job->friction;
    const ak_vec3 x0 = world(c, i);
    ak_vec3 x = x0;
    const ak_vec3 prev = ak_vec3_add(c->base[i], c->prev[i].p);
    ak_vec3 n;
    float depth;
    for (size_t k = 0; k < job->plane_count; ++k) {
        ak_vec3 pn = job->planes[k].normal;
        pn = ak_vec3_length_sq(pn) > 0.0f ? ak_vec3_normalize(pn) : ak_vec3_make(0, 1, 0);
        const float d = ak_vec3_dot(pn, x) - job->planes[k].offset - th;
        if (d < 0.0f) {
            x = ak_vec3_madd(x, pn, -d);
            x = apply_friction(x, prev, pn, -d, mu);
        }
    }
    for (size_t k = 0; k < job->sphere_count; ++k)
        if (push_sphere(&x, job->spheres[k].center, job->spheres[k].radius + th, &n, &depth))
            x = apply_friction(x, prev, n, depth, mu);
    for (size_t k = 0; k < job->capsule_count; ++k) {
        const ak_cloth_capsule* cap = &job->capsules[k];
        const ak_vec3 ab = ak_vec3_sub(cap->b, cap->a);
        const float l2 = ak_vec3_length_sq(ab);
        const float t = l2 > 0.0f ? ak_clampf(ak_vec3_dot(ak_vec3_sub(x, cap->a), ab) / l2, 0.0f, 1.0f) : 0.0f;
        if (push_sphere(&x, ak_vec3_madd(cap->a, ab, t), cap->radius + th, &n, &depth))
            x = apply_friction(x, prev, n, depth, mu);
    }
    if (c->buckets) {
        const ak_cloth_collider_mesh* m = &job->mesh;
        const uint32_t h = hash_cell(cell_of(x.x, c->cell), cell_of(x.y, c->cell), cell_of(x.z, c->cell), c->buckets);
        float best = 2.0f * th;
        ak_vec3 bq = x;
        uint32_t bt = UINT32_MAX;
        for (uint32_t k = c->hash_start[h]; k < c->hash_start[h + 1]; ++k) {
            const uint32_t t = c->hash_entry[k];
            const uint32_t* o = m->indices.ptr + 3 * t;
            const ak_vec3 q = closest_on_triangle(x, m->positions.ptr[o[0]], m->positions.ptr[o[1]], m->positions.ptr[o[2]]);
            const float d = ak_vec3_distance(x, q);
            if (d < best || (d == best && t < bt)) best = d, bq = q, bt = t;
        }
        if (bt != UINT32_MAX) {
            const ak_vec3 tn = c->tri_normal[bt];
            const ak_vec3 dx = ak_vec3_sub(x, bq);
            const float side = ak_vec3_dot(dx, tn);
            if (side >= 0.0f && best < th) {
                n = best > 1e-12f ? ak_vec3_scale(dx, 1.0f / best) : tn;
                x = ak_vec3_madd(bq, n, th);
                x = apply_friction(x, prev, n, th - best, mu);
            } else if (side < 0.0f) {
                x = ak_vec3_madd(bq, tn, th);
                x = apply_friction(x, prev, tn, th + best, mu);
            }
        }
    }
    if (x.x == x0.x && x.y == x0.y && x.z == x0.z) return false;
    c->x[i].p = ak_vec3_sub(x, c->base[i]);
    return true;
}

/* ---- constraints ------------------------------------------------------------------------ */

/* The scalar variant of cloth_kernel.h: one constraint per call, the reference for the SIMD
 * variants (cloth_avx2.c, cloth_avx512.c), which give the same bits. */
#define KW 1
#define KFN static inline
typedef float KV;
typedef bool KM;
#define K_SET1(f) (f)
#define K_LOAD(p) (*(p))
#define K_STORE(p, v) (*(p) = (v))
#define K_ADD(a, b) ((a) + (b))
#define K_SUB(a, b) ((a) - (b))
#define K_MUL(a, b) ((a) * (b))
#define K_DIV(a, b) ((a) / (b))
#define K_SQRT sqrtf
#define K_ABS fabsf
#define K_NEG(a) (-(a))
#define K_LT(a, b) ((a) < (b))
#define K_GT(a, b) ((a) > (b))
#define K_NE(a, b) ((a) != (b))
#define K_EQ(a, b) ((a) == (b))
#define K_NLT(a, b) (!((a) < (b)))
#define K_MAND(m, n) ((m) && (n))
#define K_SEL(m, a, b) ((m) ? (a) : (b))
#define K_GATHER(xs, idx, v, wv)                                                                  \
    do {                                                                                          \
        const akp_px* p_ = &(xs)[*(idx)];                                                         \
        (v) = (kv3){p_->p.x, p_->p.y, p_->p.z};                                                   \
        (wv) = p_->w;                                                                             \
    } while (0)
#define K_SCATTER(xs, idx, v, wv) ((xs)[*(idx)].p = ak_vec3_make((v).x, (v).y, (v).z), (void)(wv))
#define KN(name) scalar_##name
#include "cloth_kernel.h"

float akp_dihedral(const ak_vec3 x[4], ak_vec3 grad[4]) {
    kv3 g[4];
    const ak_vec3 e = ak_vec3_sub(x[3], x[2]), a = ak_vec3_sub(x[0], x[2]), b = ak_vec3_sub(x[1], x[2]);
    KM ok;
    const float theta = scalar_dihedral((kv3){e.x, e.y, e.z}, (kv3){a.x, a.y, a.z}, (kv3){b.x, b.y, b.z}, g, &ok);
    if (grad)
        for (int q = 0; q < 4; ++q) grad[q] = ok ? ak_vec3_make(g[q].x, g[q].y, g[q].z) : ak_vec3_make(0, 0, 0);
    return ok ? theta : 0.0f;
}

/* The constraints [kb, ke) of one colour (widest blocks first, the rest one by one). */
static void solve_dist_range(const ctx* c, size_t kb, size_t ke, bool first) {
    size_t k = kb;
#if AKP_CLOTH_SIMD
    if (c->simd >= 2) k = akp_cloth_dist_avx512(&c->solve, k, ke, first);
    if (c->simd >= 1) k = akp_cloth_dist_avx2(&c->solve, k, ke, first);
#endif
    for (; k < ke; ++k) scalar_dist(&c->solve, k, first);
}

static void solve_bend_range(const ctx* c, size_t kb, size_t ke, bool first) {
    size_t k = kb;
#if AKP_CLOTH_SIMD
    if (c->simd >= 2) k = akp_cloth_bend_avx512(&c->solve, k, ke, first);
    if (c->simd >= 1) k = akp_cloth_bend_avx2(&c->solve, k, ke, first);
#endif
    for (; k < ke; ++k) scalar_bend(&c->solve, k, first);
}

/* Spring force of spring k added to acc (force accumulators) of its two particles. */
static void spring_force(const ctx* c, size_t k) {
    const ak_cloth* cl = c->c;
    const akp_dist* d = &cl->dist[k];
    const ak_vec3 e = rel(c, d->j, d->i);
    const float len = ak_vec3_length(e);
    if (len < 1e-12f) return;
    const ak_vec3 u = ak_vec3_scale(e, 1.0f / len);
    const float rel = ak_vec3_dot(ak_vec3_sub(c->v[d->j], c->v[d->i]), u);
    const ak_vec3 f = ak_vec3_scale(u, d->k * (len - d->rest) + cl->desc.spring_damping * rel); /* on i, towards j */
    c->acc[d->i] = ak_vec3_add(c->acc[d->i], f);
    c->acc[d->j] = ak_vec3_sub(c->acc[d->j], f);
}

/* ---- self-collision ------------------------------------------------------------------- */

#define SELF_MAX_NEIGHBOURS 32u

/* Rebuild the grid over the current positions (one thread). */
static void self_grid(ctx* c) {
    const ak_grid_desc gd = {.cell_size = c->self_dist};
    for (size_t v = 0; v < c->c->n; ++v) c->xs[v] = world(c, v);
    const ak_result r = ak_grid_build(&gd, (ak_vec3_cspan){c->xs, c->c->n}, c->grid_mem, &c->grid);
    if (r != AK_OK) c->grid_result = r;
}

/* Jacobi correction of particle i into acc[i]: the mean over its pairs closer than the target
 * distance (self_distance, or their rest distance when that is smaller) of the move that
 * separates them, shared by inverse mass. */
static void self_delta(const ctx* c, size_t i) {
    const ak_cloth* cl = c->c;
    ak_vec3 sum = ak_vec3_make(0, 0, 0);
    c->acc[i] = sum;
    const float wi = cl->inv_mass[i];
    if (wi == 0.0f || c->grid_result != AK_OK) return;
    uint32_t nb[SELF_MAX_NEIGHBOURS];
    size_t total = ak_grid_query(&c->grid, c->xs[i], c->self_dist, (ak_u32_span){nb, SELF_MAX_NEIGHBOURS});
    if (total > SELF_MAX_NEIGHBOURS) total = SELF_MAX_NEIGHBOURS;
    /* the grid returns neighbours in its own order: sort them so the sum is the same for any
     * grid layout (insertion sort of at most 32) */
    for (size_t a = 1; a < total; ++a)
        for (size_t b = a; b > 0 && nb[b - 1] > nb[b]; --b) {
            const uint32_t t = nb[b];
            nb[b] = nb[b - 1], nb[b - 1] = t;
        }
    int count = 0;
    for (size_t k = 0; k < total; ++k) {
        const uint32_t j = nb[k];
        if (j == i) continue;
        const float target = ak_minf(c->self_dist, ak_vec3_distance(cl->rest[i], cl->rest[j]));
        const ak_vec3 d = rel(c, i, j);
        const float l = ak_vec3_length(d);
        if (l >= target || l < 1e-9f) continue;
        const float wj = cl->inv_mass[j];
        sum = ak_vec3_madd(sum, d, (target - l) / l * wi / (wi + wj));
        ++count;
    }
    if (count) c->acc[i] = ak_vec3_scale(sum, 1.0f / (float)count);
}

/* ---- phases ----------------------------------------------------------------------------- */

/* Wind: drag and lift per triangle from the relative air velocity, a third to each corner. */
static void wind_triangles(const ctx* c, size_t b, size_t e) {
    const ak_cloth_step_job* job = c->job;
    const ak_cloth* cl = c->c;
    const float rho = job->air_density > 0.0f ? job->air_density : 1.2f;
    for (size_t t = b; t < e; ++t) {
        const uint32_t* o = cl->indices + 3 * t;
        ak_vec3 f = ak_vec3_make(0, 0, 0);
        const ak_vec3 cr = ak_vec3_cross(rel(c, o[1], o[0]), rel(c, o[2], o[0]));
        const float cl2 = ak_vec3_length(cr);
        const ak_vec3 vt = ak_vec3_scale(ak_vec3_add(c->v[o[0]], ak_vec3_add(c->v[o[1]], c->v[o[2]])), 1.0f / 3.0f);
        const ak_vec3 vr = ak_vec3_sub(vt, job->wind); /* triangle velocity relative to the air */
        const float s = ak_vec3_length(vr);
        if (cl2 > 1e-20f && s > 1e-9f) {
            const float area = 0.5f * cl2;
            ak_vec3 n = ak_vec3_scale(cr, 1.0f / cl2);
            const ak_vec3 vh = ak_vec3_scale(vr, 1.0f / s);
            float cosine = ak_vec3_dot(n, vh);
            if (cosine < 0.0f) n = ak_vec3_neg(n), cosine = -cosine; /* the side facing the motion */
            const float q = 0.5f * rho * s * s * area;
            /* drag opposes the relative motion, scaled by the area the air sees */
            f = ak_vec3_scale(vh, -q * job->drag * cosine);
            /* lift: across the relative motion, in the plane of v and n, largest at 45 degrees */
            const ak_vec3 side = ak_vec3_cross(n, vh);
            const ak_vec3 ldir = ak_vec3_cross(side, vh); /* perpendicular to vh, towards -n */
            const float ll = ak_vec3_length(ldir);
            if (ll > 1e-9f) {
                const float sine = sqrtf(ak_maxf(0.0f, 1.0f - cosine * cosine));
                f = ak_vec3_madd(f, ldir, q * job->lift * cosine * sine / ll);
            }
        }
        c->tri_force[t] = ak_vec3_scale(f, 1.0f / 3.0f);
    }
}

static void gather_wind(const ctx* c, size_t b, size_t e) {
    const ak_cloth* cl = c->c;
    for (size_t v = b; v < e; ++v) {
        ak_vec3 s = ak_vec3_make(0, 0, 0);
        for (uint32_t k = cl->vt_start[v]; k < cl->vt_start[v + 1]; ++k) s = ak_vec3_add(s, c->tri_force[cl->vt_tri[k]]);
        c->ext[v] = s;
    }
}

/* Move the kinematic particles among [vb, ve) to where they are at fraction f of the step:
 * attachments on the line from their start to their target, pins at their pin positions (as
 * displacements). Each thread places those of its own vertices, so this phase, like the
 * prediction before it, touches only the thread's vertices (run_spmd fuses it with the end of
 * the previous substep). */
static void kinematic_targets(const ctx* c, float f, size_t vb, size_t ve) {
    const ak_cloth* cl = c->c;
    for (size_t k = 0; k < cl->attach_count; ++k) {
        const uint32_t v = cl->attach[k];
        if (v < vb || v >= ve) continue;
        c->prev[v].p = c->x[v].p;
        const ak_vec3 to = ak_vec3_sub(c->job->attachment_targets.ptr[k], c->base[v]);
        c->x[v].p = f >= 1.0f ? to : ak_vec3_scale(to, f);
        c->v[v] = ak_vec3_scale(ak_vec3_sub(c->x[v].p, c->prev[v].p), 1.0f / c->h);
    }
    for (size_t k = 0; k < cl->pin_count; ++k) {
        const uint32_t v = cl->pins[k];
        if (v < vb || v >= ve) continue;
        c->prev[v].p = c->x[v].p;
        c->x[v].p = ak_vec3_sub(cl->pin_pos[k], c->base[v]);
        c->v[v] = ak_vec3_scale(ak_vec3_sub(c->x[v].p, c->prev[v].p), 1.0f / c->h);
    }
}

static bool is_free(const ak_cloth* cl, size_t v) { return cl->inv_mass[v] > 0.0f; }

/* XPBD / PBD: predict the free particles of [b, e) at the start of a substep, then place the
 * kinematic ones (substep fraction f). */
static void predict(const ctx* c, size_t b, size_t e, float f) {
    const ak_cloth* cl = c->c;
    const ak_cloth_step_job* job = c->job;
    const float h = c->h;
    for (size_t v = b; v < e; ++v) {
        if (!is_free(cl, v)) continue;
        /* damp, then accelerate: at rest (v = 0) damping then leaves the rest point alone */
        const ak_vec3 vel = ak_vec3_madd(ak_vec3_scale(c->v[v], c->decay),
                                         ak_vec3_madd(job->gravity, c->ext[v], cl->inv_mass[v]), h);
        c->prev[v].p = c->x[v].p;
        c->x[v].p = ak_vec3_madd(c->x[v].p, vel, h);
    }
    kinematic_targets(c, f, b, e);
}

/* ---- implicit Euler (Baraff & Witkin 1998) ---------------------------------------------- */

#define CG_TOLERANCE 1e-3

/* out = filter((M + h D + h^2 K) y): the springs' stiffness K_s = k (u u^T + g (I - u u^T)) and
 * damping D_s = c u u^T couple each spring's two particles; kinematic rows are filtered out. */
static void implicit_apply(const ctx* c, const double* y, double* out) {
    const ak_cloth* cl = c->c;
    const double h = c->h, hc = h * (double)cl->desc.spring_damping;
    const double* spr = c->cg + CG_VECTORS * 3 * cl->n;
    for (size_t v = 0; v < cl->n; ++v)
        for (int a = 0; a < 3; ++a) out[3 * v + a] = (double)cl->mass[v] * y[3 * v + a];
    for (size_t k = 0; k < cl->dist_count; ++k) {
        const double* sp = spr + 4 * k;
        if (sp[3] < 0.0) continue;
        const size_t i = cl->dist[k].i, j = cl->dist[k].j;
        const double hk = h * h * (double)cl->dist[k].k;
        const double dy[3] = {y[3 * i] - y[3 * j], y[3 * i + 1] - y[3 * j + 1], y[3 * i + 2] - y[3 * j + 2]};
        const double ud = sp[0] * dy[0] + sp[1] * dy[1] + sp[2] * dy[2];
        for (int a = 0; a < 3; ++a) {
            const double t = (hc + hk) * ud * sp[a] + hk * sp[3] * (dy[a] - ud * sp[a]);
            out[3 * i + a] += t;
            out[3 * j + a] -= t;
        }
    }
    for (size_t v = 0; v < cl->n; ++v)
        if (!is_free(cl, v)) out[3 * v] = out[3 * v + 1] = out[3 * v + 2] = 0.0;
}

static double cg_dot(const double* a, const double* b, size_t m) {
    double s = 0.0;
    for (size_t k = 0; k < m; ++k) s += a[k] * b[k];
    return s;
}

/* One backward-Euler substep of the springs, linearised at the substep's start: solve
 * (M + h D + h^2 K) dv = h (f - h K v) by Jacobi-preconditioned conjugate gradients with the
 * kinematic particles' dv fixed (Baraff & Witkin's filtered CG), then v += dv, x += h v. Runs
 * on one thread (the step runs the implicit solver on the calling thread only). */
static void implicit_substep(ctx* c, float f) {
    const ak_cloth* cl = c->c;
    const ak_cloth_step_job* job = c->job;
    const size_t n = cl->n, m3 = 3 * n;
    const double h = c->h, cd = (double)cl->desc.spring_damping;
    double* const dv = c->cg + CG_DV * m3;
    double* const r = c->cg + CG_R * m3;
    double* const cv = c->cg + CG_C * m3;
    double* const q = c->cg + CG_Q * m3;
    double* const sv = c->cg + CG_S * m3;
    double* const b = c->cg + CG_B * m3;
    double* const pre = c->cg + CG_PRE * m3;
    double* const spr = c->cg + CG_VECTORS * m3;
    /* forces at the substep's start (velocities damped first, as the other solvers do), and K v */
    for (size_t v = 0; v < n; ++v) {
        if (is_free(cl, v)) c->v[v] = ak_vec3_scale(c->v[v], c->decay);
        const ak_vec3 fe = is_free(cl, v) ? ak_vec3_madd(c->ext[v], job->gravity, cl->mass[v]) : ak_vec3_make(0, 0, 0);
        b[3 * v] = fe.x, b[3 * v + 1] = fe.y, b[3 * v + 2] = fe.z;
        q[3 * v] = q[3 * v + 1] = q[3 * v + 2] = 0.0;
        pre[3 * v] = pre[3 * v + 1] = pre[3 * v + 2] = cl->mass[v];
    }
    for (size_t k = 0; k < cl->dist_count; ++k) {
        const akp_dist* d = &cl->dist[k];
        double* sp = spr + 4 * k;
        const ak_vec3 e = rel(c, d->j, d->i);
        const double ex = e.x, ey = e.y, ez = e.z, l = sqrt(ex * ex + ey * ey + ez * ez);
        if (!(l > 1e-12)) {
            sp[3] = -1.0;
            continue;
        }
        sp[0] = ex / l, sp[1] = ey / l, sp[2] = ez / l;
        sp[3] = fmax(0.0, 1.0 - (double)d->rest / l);
        const ak_vec3 vi = c->v[d->i], vj = c->v[d->j];
        const double dvv[3] = {(double)vi.x - vj.x, (double)vi.y - vj.y, (double)vi.z - vj.z};
        const double ud = sp[0] * dvv[0] + sp[1] * dvv[1] + sp[2] * dvv[2];
        const double fs = (double)d->k * (l - (double)d->rest) - cd * ud; /* on i, along u (towards j) */
        for (int a = 0; a < 3; ++a) {
            b[3 * d->i + a] += fs * sp[a];
            b[3 * d->j + a] -= fs * sp[a];
            const double t = (double)d->k * (ud * sp[a] + sp[3] * (dvv[a] - ud * sp[a])); /* K_s (v_i - v_j) */
            q[3 * d->i + a] += t;
            q[3 * d->j + a] -= t;
            const double dg = h * cd * sp[a] * sp[a] + h * h * (double)d->k * (sp[a] * sp[a] + sp[3] * (1.0 - sp[a] * sp[a]));
            pre[3 * d->i + a] += dg;
            pre[3 * d->j + a] += dg;
        }
    }
    /* b = filter(h (f - h K v)); dv starts at the kinematic particles' required change */
    const ak_cloth_step_job* jb = job;
    for (size_t v = 0; v < n; ++v)
        for (int a = 0; a < 3; ++a) {
            b[3 * v + a] = is_free(cl, v) ? h * (b[3 * v + a] - h * q[3 * v + a]) : 0.0;
            pre[3 * v + a] = is_free(cl, v) && pre[3 * v + a] > 0.0 ? 1.0 / pre[3 * v + a] : 0.0;
            dv[3 * v + a] = 0.0;
        }
    for (size_t k = 0; k < cl->attach_count; ++k) {
        const uint32_t v = cl->attach[k];
        const ak_vec3 to = ak_vec3_sub(jb->attachment_targets.ptr[k], c->base[v]);
        const ak_vec3 dt = f >= 1.0f ? to : ak_vec3_scale(to, f);
        const ak_vec3 need = ak_vec3_sub(ak_vec3_scale(ak_vec3_sub(dt, c->x[v].p), (float)(1.0 / h)), c->v[v]);
        dv[3 * v] = need.x, dv[3 * v + 1] = need.y, dv[3 * v + 2] = need.z;
    }
    for (size_t k = 0; k < cl->pin_count; ++k) {
        const uint32_t v = cl->pins[k];
        const ak_vec3 dt = ak_vec3_sub(cl->pin_pos[k], c->base[v]);
        const ak_vec3 need = ak_vec3_sub(ak_vec3_scale(ak_vec3_sub(dt, c->x[v].p), (float)(1.0 / h)), c->v[v]);
        dv[3 * v] = need.x, dv[3 * v + 1] = need.y, dv[3 * v + 2] = need.z;
    }
    /* filtered PCG */
    implicit_apply(c, dv, q);
    for (size_t k = 0; k < m3; ++k) {
        r[k] = b[k] - q[k];
        sv[k] = pre[k] * b[k];
    }
    const double delta0 = cg_dot(b, sv, m3);
    for (size_t k = 0; k < m3; ++k) cv[k] = sv[k] = pre[k] * r[k];
    double delta = cg_dot(r, sv, m3);
    for (uint32_t it = 0; it < c->cg_max && delta > CG_TOLERANCE * CG_TOLERANCE * delta0 && delta > 0.0; ++it) {
        implicit_apply(c, cv, q);
        const double cq = cg_dot(cv, q, m3);
        if (!(cq > 0.0)) break;
        const double alpha = delta / cq;
        for (size_t k = 0; k < m3; ++k) {
            dv[k] += alpha * cv[k];
            r[k] -= alpha * q[k];
            sv[k] = pre[k] * r[k];
        }
        const double dnew = cg_dot(r, sv, m3);
        const double beta = dnew / delta;
        for (size_t k = 0; k < m3; ++k) cv[k] = sv[k] + beta * cv[k];
        delta = dnew;
    }
    /* v += dv, x += h v (free particles; kinematic ones are placed by kinematic_targets) */
    for (size_t v = 0; v < n; ++v) {
        if (!is_free(cl, v)) continue;
        const ak_vec3 vel = ak_vec3_make((float)((double)c->v[v].x + dv[3 * v]), (float)((double)c->v[v].y + dv[3 * v + 1]),
                                         (float)((double)c->v[v].z + dv[3 * v + 2]));
        c->prev[v].p = c->x[v].p;
        c->v[v] = vel;
        c->x[v].p = ak_vec3_madd(c->x[v].p, vel, (float)h);
    }
}

static void run_spmd(ctx* c, unsigned t) {
    const ak_cloth* cl = c->c;
    const ak_cloth_step_job* job = c->job;
    const size_t n = cl->n;
    const float h = c->h;
    size_t b, e;
    const bool wind = (job->drag > 0.0f || job->lift > 0.0f) && cl->tri_count > 0;
    size_t tb, te;
    range(n, t, c->T, &b, &e);
    range(cl->tri_count, t, c->T, &tb, &te);
    /* the data check of ak_cloth_step_validate, each thread its vertices */
    bool ok = true;
    for (size_t v = b; v < e; ++v) ok = vertex_finite(job, v) && ok;
    c->bad[t] = !ok;
    /* displacements start at the residuals (the part of the position the float missed) */
    ak_vec3* const res = job->position_residuals.ptr;
    for (size_t v = b; v < e; ++v) {
        const ak_vec3 d0 = res && cl->inv_mass[v] > 0.0f ? res[v] : ak_vec3_make(0, 0, 0);
        c->x[v] = (akp_px){d0, cl->inv_mass[v]};
        c->prev[v] = (akp_px){d0, 0.0f};
    }
    memset(c->ext + b, 0, (e - b) * sizeof(ak_vec3));
    /* the constraints' vectors at the start of the step (XPBD/PBD solves add the displacements) */
    if (!akp_spring_solver(cl->desc.solver)) {
        const ak_vec3* x0 = c->base;
        size_t kb, ke;
        range(cl->dist_count, t, c->T, &kb, &ke);
        for (size_t k = kb; k < ke; ++k) {
            const ak_vec3 o = ak_vec3_sub(x0[cl->dist_i[k]], x0[cl->dist_j[k]]);
            c->solve.dist_off[0][k] = o.x, c->solve.dist_off[1][k] = o.y, c->solve.dist_off[2][k] = o.z;
        }
        range(cl->bend_count, t, c->T, &kb, &ke);
        for (size_t k = kb; k < ke; ++k) {
            const ak_vec3 x2 = x0[cl->bend_p[2][k]];
            ak_vec3 o[3];
            if (c->solve.iso) {
                o[0] = ak_vec3_make(0, 0, 0);
                const int qs[3] = {0, 1, 3};
                for (int q = 0; q < 3; ++q)
                    o[0] = ak_vec3_add(o[0], ak_vec3_scale(ak_vec3_sub(x0[cl->bend_p[qs[q]][k]], x2), cl->bend_K[qs[q]][k]));
            } else {
                o[0] = ak_vec3_sub(x0[cl->bend_p[3][k]], x2);
                o[1] = ak_vec3_sub(x0[cl->bend_p[0][k]], x2);
                o[2] = ak_vec3_sub(x0[cl->bend_p[1][k]], x2);
            }
            for (int q = 0; q < (c->solve.iso ? 1 : 3); ++q) {
                c->solve.bend_off[3 * q][k] = o[q].x;
                c->solve.bend_off[3 * q + 1][k] = o[q].y;
                c->solve.bend_off[3 * q + 2][k] = o[q].z;
            }
        }
    }
    barrier(c);
    /* every thread checked its vertices' data: a non-finite one anywhere stops the step before
     * anything of the caller's is written (ak_cloth_step_run returns AK_ERR_BAD_DATA) */
    for (unsigned u = 0; u < c->T; ++u)
        if (c->bad[u]) return;
    const bool springs = cl->desc.solver == AK_CLOTH_SPRINGS, implicit = cl->desc.solver == AK_CLOTH_IMPLICIT;
    /* XPBD / PBD without wind or self-collision: a substep's last phase (collisions and
     * velocities, per vertex) and the next one's prediction (per vertex, kinematic particles
     * included) touch only each thread's own vertices, so they run as one phase, saving a meeting
     * per substep (and the one before the end of the step) */
    const bool fuse = !wind && !c->self;
    for (uint32_t s = 0; s < c->substeps; ++s) {
        const float f = (float)(s + 1) / (float)c->substeps;
        /* wind each substep: drag acts like a damper of rate rho C_d A |v| / m, which an
         * explicit force only follows stably when that rate times the step is small */
        if (wind) {
            wind_triangles(c, tb, te);
            barrier(c);
            gather_wind(c, b, e);
            barrier(c);
        }
        if (springs || implicit) {
            if (implicit) implicit_substep(c, f); /* one thread (T = 1) */
            else {
            for (size_t v = b; v < e; ++v)
                c->acc[v] = is_free(cl, v) ? ak_vec3_madd(c->ext[v], job->gravity, cl->mass[v]) : ak_vec3_make(0, 0, 0);
            barrier(c);
            for (int col = 0; col <= AKP_MAX_COLORS; ++col) {
                const size_t cb = cl->dist_color[col], ce = cl->dist_color[col + 1];
                if (cb == ce) continue;
                size_t kb, ke;
                if (col == AKP_SERIAL_COLOR) kb = t == 0 ? cb : ce, ke = ce;
                else range(ce - cb, t, c->T, &kb, &ke), kb += cb, ke += cb;
                for (size_t k = kb; k < ke; ++k) spring_force(c, k);
                barrier(c);
            }
            for (size_t v = b; v < e; ++v) {
                if (!is_free(cl, v)) continue;
                const ak_vec3 vel = ak_vec3_madd(ak_vec3_scale(c->v[v], c->decay), c->acc[v], h * cl->inv_mass[v]);
                c->prev[v].p = c->x[v].p;
                c->v[v] = vel;
                c->x[v].p = ak_vec3_madd(c->x[v].p, vel, h);
            }
            }
            kinematic_targets(c, f, b, e);
            barrier(c);
            if (c->self) {
                if (t == 0) self_grid(c);
                barrier(c);
                for (size_t v = b; v < e; ++v) self_delta(c, v);
                barrier(c);
            }
            for (size_t v = b; v < e; ++v) {
                if (!is_free(cl, v)) continue;
                bool moved = false;
                if (c->self && (c->acc[v].x != 0.0f || c->acc[v].y != 0.0f || c->acc[v].z != 0.0f)) {
                    c->x[v].p = ak_vec3_add(c->x[v].p, c->acc[v]);
                    moved = true;
                }
                if (collide(c, v) || moved) c->v[v] = ak_vec3_scale(ak_vec3_sub(c->x[v].p, c->prev[v].p), 1.0f / h);
            }
            barrier(c);
            continue;
        }
        /* XPBD / PBD: predict (when fused, the previous substep's last phase did) */
        if (!fuse || s == 0) predict(c, b, e, f);
        barrier(c);
        for (uint32_t it = 0; it < c->iterations; ++it) {
            for (int col = 0; col <= AKP_MAX_COLORS; ++col) {
                size_t kb, ke;
                if (!color_share(cl->dist_color, col, t, c->T, &kb, &ke)) continue;
                if (col == AKP_SERIAL_COLOR)
                    for (size_t k = kb; k < ke; ++k) scalar_dist(&c->solve, k, it == 0);
                else
                    solve_dist_range(c, kb, ke, it == 0);
                barrier(c);
            }
            for (int col = 0; col <= AKP_MAX_COLORS; ++col) {
                size_t kb, ke;
                if (!color_share(cl->bend_color, col, t, c->T, &kb, &ke)) continue;
                if (col == AKP_SERIAL_COLOR)
                    for (size_t k = kb; k < ke; ++k) scalar_bend(&c->solve, k, it == 0);
                else
                    solve_bend_range(c, kb, ke, it == 0);
                barrier(c);
            }
            if (cl->lra_anchor) {
                for (size_t v = b; v < e; ++v) {
                    const uint32_t a = cl->lra_anchor[v];
                    if (a == UINT32_MAX) continue;
                    const ak_vec3 d = rel(c, v, a);
                    const float l = ak_vec3_length(d);
                    if (l > cl->lra_dist[v]) /* x_v = x_a + d * lra / l */
                        c->x[v].p = ak_vec3_add(ak_vec3_add(ak_vec3_sub(c->base[a], c->base[v]), c->x[a].p),
                                                ak_vec3_scale(d, cl->lra_dist[v] / l));
                }
                barrier(c);
            }
        }
        if (c->self) {
            if (t == 0) self_grid(c);
            barrier(c);
            for (size_t v = b; v < e; ++v) self_delta(c, v);
            barrier(c);
        }
        for (size_t v = b; v < e; ++v) {
            if (is_free(cl, v)) {
                if (c->self) c->x[v].p = ak_vec3_add(c->x[v].p, c->acc[v]);
                collide(c, v);
            }
            c->v[v] = ak_vec3_scale(ak_vec3_sub(c->x[v].p, c->prev[v].p), 1.0f / h);
        }
        if (fuse) {
            /* no meeting: the next phase (the next substep's prediction, or the end of the
             * step) reads and writes only this thread's vertices */
            if (s + 1 < c->substeps) predict(c, b, e, (float)(s + 2) / (float)c->substeps);
            continue;
        }
        barrier(c);
    }
    /* the end of the step: start + displacement (nobody reads the start positions any more) */
    bool finite = true;
    for (size_t v = b; v < e; ++v) {
        const ak_vec3 x0 = job->positions.ptr[v], d = c->x[v].p, x1 = ak_vec3_add(x0, d);
        job->positions.ptr[v] = x1;
        /* what the rounding lost: d - (x1 - x0), both differences exact for |d| << |x0|
         * (Sterbenz); kept when the caller keeps residuals (kinematic particles: none).
         * Velocities stay the integrated ones */
        if (res) res[v] = cl->inv_mass[v] == 0.0f ? ak_vec3_make(0, 0, 0) : ak_vec3_sub(d, ak_vec3_sub(x1, x0));
        finite = finite && ak_vec3_is_finite(d) && ak_vec3_is_finite(c->v[v]);
    }
    c->finite[t] = finite;
}

const char* ak_cloth_simd_name(void) {
#if AKP_CLOTH_SIMD
    if (akp_cloth_have_avx512()) return "avx512";
    if (akp_cloth_have_avx2()) return "avx2";
#endif
    return "scalar";
}

static void* worker_main(void* arg) {
    worker* w = (worker*)arg;
    run_spmd(w->c, w->t);
    return NULL;
}

ak_result ak_cloth_step_run(const ak_cloth_step_job* job) {
    ak_result r = validate(job, false); /* the vertices' data: checked on the threads (run_spmd) */
    if (r != AK_OK) return r;
    const ak_cloth* cl = job->cloth;
    const size_t mesh_tris = job->mesh.indices.count / 3;
    const layout l = make_layout(cl, mesh_tris, job);
    uint8_t* base = job->scratch.ptr;
    base += (16u - ((uintptr_t)base & 15u)) & 15u;
    ctx c;
    memset(&c, 0, sizeof c);
    c.job = job;
    c.c = cl;
    c.substeps = job->substeps ? job->substeps : 10;
    c.iterations = job->iterations ? job->iterations : 1;
    c.h = job->dt / (float)c.substeps;
    c.decay = expf(-job->damping * c.h);
    c.thickness = job->thickness > 0.0f ? job->thickness : 0.01f;
    c.x = (akp_px*)(base + l.xw);
    c.xs = (ak_vec3*)(base + l.xs);
    c.v = job->velocities.ptr;
    c.prev = (akp_px*)(base + l.prev);
    c.ext = (ak_vec3*)(base + l.ext);
    c.acc = (ak_vec3*)(base + l.acc);
    c.lambda = (float*)(base + l.lambda);
    c.tri_force = (ak_vec3*)(base + l.tri_force);
    c.hash_start = (uint32_t*)(base + l.hash_start);
    c.hash_entry = (uint32_t*)(base + l.hash_entry);
    c.tri_normal = (ak_vec3*)(base + l.tri_normal);
    c.buckets = l.buckets;
    c.self = job->self_collision;
    c.self_dist = self_distance(job);
    c.grid_mem = (ak_u8_span){base + l.grid, l.grid_size};
    c.cg = (double*)(base + l.cg);
    c.cg_max = job->iterations ? job->iterations : 100;
    /* displacements start at the residuals (the part of the position the float missed) */
    c.base = job->positions.ptr;
    c.solve = (akp_solve){.cl = cl, .x = c.x, .prev = c.prev, .lambda = c.lambda, .h = c.h, .h2 = c.h * c.h,
                          .beta = cl->desc.constraint_damping, .pbd_stiffness = cl->desc.pbd_stiffness,
                          .bend_alpha = 1.0f / cl->desc.dihedral_stiffness, .pbd = cl->desc.solver == AK_CLOTH_PBD,
                          .damped = cl->desc.constraint_damping > 0.0f,
                          .iso = cl->desc.bending == AK_CLOTH_BEND_ISOMETRIC};
    for (int q = 0; q < 3; ++q) c.solve.dist_off[q] = (float*)(base + l.off + (size_t)q * l.dist_stride);
    for (int q = 0; q < (c.solve.iso ? 3 : 9); ++q)
        c.solve.bend_off[q] = (float*)(base + l.off + 3 * l.dist_stride + (size_t)q * l.bend_stride);
    c.simd = 0;
#if AKP_CLOTH_SIMD
    {
        const ak_cloth_simd limit = job->simd_limit == AK_CLOTH_SIMD_DEFAULT ? AK_CLOTH_SIMD_AVX512 : job->simd_limit;
        if (limit >= AK_CLOTH_SIMD_AVX512 && akp_cloth_have_avx512()) c.simd = 2;
        else if (limit >= AK_CLOTH_SIMD_AVX2 && akp_cloth_have_avx2()) c.simd = 1;
    }
#endif
    if (mesh_tris) build_hash(&c, 2.0f * c.thickness);
    unsigned want = job->thread_count > 1 ? job->thread_count : 1;
    if (cl->desc.solver == AK_CLOTH_IMPLICIT) want = 1;
    if (want > 1 && !job->exact_thread_count && cl->desc.solver != AK_CLOTH_SPRINGS) {
        /* one thread per THREAD_MIN_PER_COLOR constraints of an average colour */
        size_t colors = 0;
        for (int k = 0; k <= AKP_MAX_COLORS; ++k)
            colors += (cl->dist_color[k + 1] > cl->dist_color[k]) + (cl->bend_color[k + 1] > cl->bend_color[k]);
        const size_t per_color = colors ? (cl->dist_count + cl->bend_count) / colors : 0;
        const size_t fit = per_color / THREAD_MIN_PER_COLOR;
        if (fit < want) want = fit > 1 ? (unsigned)fit : 1;
    }
    if ((size_t)want > cl->n) want = cl->n ? (unsigned)cl->n : 1;
    /* the library's worker team runs the other threads' shares (src/tasks.h); when it cannot
     * give each its own thread the caller runs the whole step alone */
    worker ws[MAX_THREADS];
    akp_team_run team;
    c.T = want;
    if (want > 1) {
        for (unsigned t = 0; t < want; ++t) ws[t] = (worker){&c, t};
        akp_barrier_init(&c.bar, want);
        if (!akp_team_begin(&team, worker_main, ws, sizeof(worker), want)) c.T = 1;
    }
    run_spmd(&c, 0);
    if (want > 1) {
        akp_team_end(&team);
        akp_barrier_destroy(&c.bar);
    }
    /* the end of the step (each thread's vertices: run_spmd), then kinematic particles exactly
     * at their targets */
    bool finite = true;
    for (unsigned t = 0; t < c.T; ++t) {
        if (c.bad[t]) return AK_ERR_BAD_DATA; /* nothing written */
        finite = finite && c.finite[t];
    }
    for (size_t k = 0; k < cl->pin_count; ++k) job->positions.ptr[cl->pins[k]] = cl->pin_pos[k];
    for (size_t k = 0; k < cl->attach_count; ++k) job->positions.ptr[cl->attach[k]] = job->attachment_targets.ptr[k];
    if (!finite) return AK_ERR_NO_CONVERGENCE;
    if (job->out_normals.ptr)
        ak_cloth_normals(cl, (ak_vec3_cspan){job->positions.ptr, cl->n}, job->out_normals);
    return AK_OK;
}
