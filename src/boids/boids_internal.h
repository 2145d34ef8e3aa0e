/* Boids internals shared by boids.c (rules, integration) and search.c (neighbour search).
 * Never installed. */
#ifndef ANIMKIT_BOIDS_INTERNAL_H
#define ANIMKIT_BOIDS_INTERNAL_H

#include <math.h>
#include <stdint.h>

#include <animkit/boids.h>
#include <animkit/grid.h>

#include "../internal.h"

/* Fixed-point scales of the neighbour sums (see species_runtime). Each contribution is clamped
 * to +-AKP_BOIDS_FIX_CLAMP, so 1e8 agents' worth of sums stay inside int64. */
#define AKP_BOIDS_FIX 268435456.0f     /* 2^28 per unit (velocity in max_speed, offset in radius) */
#define AKP_BOIDS_FIX_SEP 16777216.0f  /* 2^24 per 1/separation_radius */
#define AKP_BOIDS_FIX_CLAMP 17179869184.0f /* 2^34 */

/* A species ready for the hot loop. */
typedef struct akp_boids_sp {
    ak_boids_species s;            /* resolved */
    float rs2, ra2, rc2;           /* squared rule radii (0 when the rule is off) */
    float rn2;                     /* squared flock radius: the largest of the three */
    float fr2, pr2;                /* squared flee / pursue radii (0 when off) */
    float query_radius;            /* the farthest this species looks */
    float cos2;                    /* squared cosine of half the view angle */
    int fov;                       /* 0 all around, 1 half angle <= 90 deg, 2 wider */
    float dmin2;                   /* separation distance clamp, squared */
    float sep_scale, ali_scale, coh_scale;
} akp_boids_sp;

/* Neighbour sums an agent received in the symmetric pair pass (spatial order): the same
 * fixed-point sums as akp_boids_gather, counts packed two per word (ns | na << 32,
 * nc | nflock << 32). */
typedef struct akp_boids_acc {
    int64_t sep[3], ali[3], coh[3];
    uint64_t n01, n23;
    int64_t pad; /* 96 bytes: the AVX-512 kernel adds a pair's credits as 8 + 4 int64 lanes */
} akp_boids_acc;

/* Per-step context: the job, resolved species, the search state. */
typedef struct akp_boids_ctx {
    const ak_boids_step_job* job;
    const ak_boids_params* params;
    size_t n;
    ak_boids_bounds bounds; /* resolved mode */
    akp_boids_sp sp[AK_BOIDS_MAX_SPECIES];
    float search_radius;    /* largest query radius over species (0: nobody looks) */
    /* Grid path (use_naive false). The hashed grid is built only for sparse flocks; on the
     * dense path grid.cell_size alone is set (ak_grid_cell_of). */
    ak_grid grid;
    int rings;              /* cells visited on each side of an agent's cell */
    const int64_t* sqv;     /* [3n] velocities, fixed point (alignment sums), in sorted order */
    const uint8_t* ssp;     /* [n] species in sorted order */
    /* Spatial layout, built when the occupied cells' bounding box is small enough: the agents
     * re-sorted by cell in (z, y, x) order over that box, so the cells of one row of a
     * neighbourhood are one contiguous range and no candidate is copied. dstart[cell] is the
     * first agent of box cell (x, y, z) (cell = (z * dim[1] + y) * dim[0] + x), dstart[cell + 1]
     * its end; empty cells are empty ranges. "Sorted order" above is this order when dstart is
     * set, else the grid's. NULL when not built (the grid's hashed cells are used). */
    uint32_t* dstart;
    int32_t dense_min[3];
    int32_t dense_dim[3];
    const float *sx, *sy, *sz; /* [n] positions in spatial order */
    const ak_vec3* sv;         /* [n] velocities in spatial order */
    const uint32_t* sj;        /* [n] the agent's index in the caller's arrays */
    bool avx512;               /* the spatial path runs the AVX-512 kernels */
    bool avx2;                 /* else the symmetric pass runs the AVX2 pair kernel */
    bool one_species;          /* species_count == 1 */
    /* Symmetric pair pass (dense layout, one species, no k cap, flee or pursue, one ring):
     * acc[n] holds what each agent received from the pairs found by agents before it. */
    bool sym;
    akp_boids_acc* acc;
    akp_boids_acc* spill;    /* credits across thread boundaries (in the grid's unused memory) */
    size_t spill_cap;        /* entries spill holds */
    bool use_spill;          /* set by akp_boids_sym_clear: the deferred rows fit spill */
    /* The dense layout's rows (row r: z = r / dim[1], y = r % dim[1]) split into the step's
     * parts by estimated work (akp_boids_partition): part p walks rows [part_row[p],
     * part_row[p + 1]); in the symmetric pass its rows [part_row[p], defer_row[p]) also
     * receive from part p - 1 and integrate in akp_boids_sym_finish (defer_row[0] =
     * part_row[0]). part_count: the parts it was made for (0: none). */
    uint32_t part_row[65], defer_row[65];
    uint32_t part_count;
    bool sym_zeroed;         /* the deferred rows' sums (acc or spill) were zeroed in the fill */
    /* The spatial arrays, writable, for akp_boids_search_fill. */
    float *fill_sx, *fill_sy, *fill_sz;
    ak_vec3* fill_sv;
    uint8_t* fill_sp;
    int64_t* fill_qv;
} akp_boids_ctx;

/* What one agent gathers from its neighbours. */
typedef struct akp_boids_gather {
    const akp_boids_sp* sp;
    uint32_t i;                    /* the agent (original index) */
    uint32_t self_k;               /* its index in the spatial arrays, UINT32_MAX when not known */
    uint8_t species;
    ak_vec3 p, v;
    float v2;
    int64_t sep[3], ali[3], coh[3];
    uint32_t ns, na, nc;           /* neighbours per rule */
    uint32_t nflock;               /* flock neighbours (after the k cap) */
    uint32_t kcount;               /* k-nearest candidates held */
    float kd2[AK_BOIDS_MAX_K];
    uint32_t kj[AK_BOIDS_MAX_K];
    float flee_d2, prey_d2;
    uint32_t flee_j, prey_j;       /* nearest predator / prey, UINT32_MAX when none */
    uint32_t* list;                /* neighbour list mode: flock neighbours appended here */
    uint32_t list_count;
} akp_boids_gather;

ak_result akp_boids_validate_inputs(const ak_boids_step_job* job, bool need_wander);
ak_boids_bounds akp_boids_bounds_mode(const ak_boids_params* p);
void akp_boids_ctx_init(akp_boids_ctx* c, const ak_boids_step_job* job);
void akp_boids_run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count);
uint32_t akp_boids_threads(uint32_t requested, size_t n);

/* Candidates of one agent that passed the distance test, before the neighbour rules: spatial
 * index, d2 and the offset (candidate - agent). */
#define AKP_BOIDS_HIT_CAP 512
typedef struct akp_boids_hits {
    uint32_t k[AKP_BOIDS_HIT_CAP];
    float d2[AKP_BOIDS_HIT_CAP], dx[AKP_BOIDS_HIT_CAP], dy[AKP_BOIDS_HIT_CAP], dz[AKP_BOIDS_HIT_CAP];
} akp_boids_hits;

/* search_avx512.c (x86-64 GCC/Clang without AK_NO_SIMD; elsewhere have_avx512 is false).
 * have_avx512: this CPU runs the kernels (AVX-512 F and DQ).
 * filter: appends the candidates t in [begin, end) of the spatial arrays with d2 < q2 to h at
 * `at` and returns how many; it stores 16 entries at a time, so h needs room for 16 more.
 * visit: the register-sum fast path of visit_hits (one species, no cap, no list, no flee or
 * pursue) for hits [0, count): the same tests and the same integer sums as the scalar code. */
bool akp_boids_have_avx512(void);
uint32_t akp_boids_filter_avx512(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end, ak_vec3 p,
                                 float q2, akp_boids_hits* h, uint32_t at);
void akp_boids_visit_avx512(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h, uint32_t count);
/* filter over the rows [begin[r], end[r]), r < rows, in one call; h needs room for all their
 * candidates and 16 more. */
uint32_t akp_boids_filter_rows_avx512(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                      const uint32_t* end, uint32_t rows, ak_vec3 p, float q2, akp_boids_hits* h,
                                      uint32_t at);

/* A cell's forward candidates packed side by side (positions and spatial index), so the
 * 16-lane filter runs full instead of over short rows; 16 entries of slack after count. */
#define AKP_BOIDS_PACK_CAP 384
typedef struct akp_boids_packed {
    float x[AKP_BOIDS_PACK_CAP + 16], y[AKP_BOIDS_PACK_CAP + 16], z[AKP_BOIDS_PACK_CAP + 16];
    uint32_t k[AKP_BOIDS_PACK_CAP + 16];
} akp_boids_packed;
/* Packs the rows [begin[r], end[r]) (at most AKP_BOIDS_PACK_CAP candidates in all) into b;
 * returns the count. */
uint32_t akp_boids_pack_rows_avx512(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                    const uint32_t* end, uint32_t rows, akp_boids_packed* b);
/* The filter over the row [begin, end) of the spatial arrays, then the packed candidates
 * [0, count): hits appended at `at`, their number returned (h needs room for all of them
 * and 32 more). */
uint32_t akp_boids_filter_packed_avx512(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end,
                                        const akp_boids_packed* b, uint32_t count, ak_vec3 p, float q2,
                                        akp_boids_hits* h, uint32_t at);

/* Where the symmetric pass credits agent t (spatial slot): acc[t], except
 * - t >= far_begin (the next part's first slab, which that part also credits): spill[t -
 *   far_begin] when spill is set, else acc[t] by atomic adds;
 * - t < atomic_end (this part's own first slab when the part before credits it in acc): acc[t]
 *   by atomic adds (atomic_end is 0 when spill is used). */
typedef struct akp_boids_sink {
    akp_boids_acc* acc;
    akp_boids_acc* spill;
    uint32_t atomic_end, far_begin;
} akp_boids_sink;

/* The symmetric pair kernel: agent g (spatial slot g->self_k) against its forward hits
 * [0, count) (all of them other agents): g's own sums in g, what each hit receives credited
 * through sink. Same tests and integer sums as the scalar sym_hits in search.c. */
void akp_boids_sym_avx512(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h, uint32_t count,
                          const akp_boids_sink* sink);

/* integrate_simd.c: the step's integration, 8 agents at a time, for the common case
 * (akp_boids_batch_ok: the symmetric pass, no goal, leader, wander, obstacles, steer-back
 * bounds or planar flock). The agents' sums, counts, positions and velocities are copied into
 * a batch; akp_boids_integrate_avx512 writes each lane's new position and velocity to the
 * job's outputs, bit-identical to integrate() in boids.c, and returns the mask of the lanes
 * it left to the scalar code (speed below min_speed, non-finite force, wrapped position).
 * Lanes at and past n are ignored (zero them: they are computed). */
#define AKP_BOIDS_BATCH 8
typedef struct akp_boids_batch {
    uint32_t n;
    uint32_t idx[AKP_BOIDS_BATCH];
    int64_t q[9][AKP_BOIDS_BATCH]; /* sep x y z, ali x y z, coh x y z */
    uint32_t ns[AKP_BOIDS_BATCH], na[AKP_BOIDS_BATCH], nc[AKP_BOIDS_BATCH];
    float p[3][AKP_BOIDS_BATCH], v[3][AKP_BOIDS_BATCH];
} akp_boids_batch;
uint32_t akp_boids_integrate_avx512(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b);
/* The same with AVX2 (int64 -> double in two exact halves), for CPUs without AVX-512. */
uint32_t akp_boids_integrate_avx2(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b);

/* search_avx2.c (x86-64 GCC/Clang without AK_NO_SIMD; elsewhere have_avx2 is false): the
 * symmetric pair kernel for CPUs with AVX2 but not AVX-512, over hits with their offsets (the
 * AVX2 or SSE2 filter's); same tests and integer sums as the scalar sym_hits in search.c. */
bool akp_boids_have_avx2(void);
/* The AVX2 packing and distance filters, as their AVX-512 namesakes (hits with k, d2 and the
 * offsets; h needs room for 8 more than the hits; the packed arrays are zero from count to
 * the next multiple of 8). */
uint32_t akp_boids_pack_rows_avx2(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                  const uint32_t* end, uint32_t rows, akp_boids_packed* b);
uint32_t akp_boids_filter_rows_avx2(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                    const uint32_t* end, uint32_t rows, ak_vec3 p, float q2, akp_boids_hits* h,
                                    uint32_t at);
uint32_t akp_boids_filter_packed_avx2(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end,
                                      const akp_boids_packed* b, uint32_t count, ak_vec3 p, float q2,
                                      akp_boids_hits* h, uint32_t at);
void akp_boids_sym_avx2(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h, uint32_t count,
                        const akp_boids_sink* sink);

/* g += a kernel's neighbour sums v (sep x y z, ali x y z, coh x y z) and counts. (The AVX-512
 * kernels add their lane reductions to g directly: building v there cost 3-4% of a step.) */
static inline void akp_boids_gather_add(akp_boids_gather* g, const int64_t v[9], uint32_t ns, uint32_t na, uint32_t nc,
                                        uint32_t nf) {
    for (int a = 0; a < 3; ++a) {
        g->sep[a] += v[a];
        g->ali[a] += v[3 + a];
        g->coh[a] += v[6 + a];
    }
    g->ns += ns;
    g->na += na;
    g->nc += nc;
    g->nflock += nf;
}

/* A += the credits of one pair, atomically when another thread may touch A. */
static inline void akp_boids_credit(akp_boids_acc* A, const int64_t v[9], uint64_t n01, uint64_t n23, bool atomic) {
    if (!atomic) {
        for (int a = 0; a < 3; ++a) {
            A->sep[a] += v[a];
            A->ali[a] += v[3 + a];
            A->coh[a] += v[6 + a];
        }
        A->n01 += n01;
        A->n23 += n23;
        return;
    }
    for (int a = 0; a < 3; ++a) {
        __atomic_fetch_add(&A->sep[a], v[a], __ATOMIC_RELAXED);
        __atomic_fetch_add(&A->ali[a], v[3 + a], __ATOMIC_RELAXED);
        __atomic_fetch_add(&A->coh[a], v[6 + a], __ATOMIC_RELAXED);
    }
    __atomic_fetch_add(&A->n01, n01, __ATOMIC_RELAXED);
    __atomic_fetch_add(&A->n23, n23, __ATOMIC_RELAXED);
}

/* search.c */
size_t akp_boids_search_scratch_size(const ak_boids_step_job* job);
/* Spatial slots [n part / parts, n (part + 1) / parts) of the dense layout filled from the
 * caller's arrays through sj (prepare runs it, over threads for large steps). */
typedef struct akp_boids_fill_task {
    const akp_boids_ctx* c;
    size_t part, parts;
} akp_boids_fill_task;
void akp_boids_search_fill(const akp_boids_ctx* c, size_t part, size_t parts);
/* The search structures (unless use_naive) in scratch: the dense spatial layout straight from
 * the positions, or, for sparse flocks, the hashed grid. */
ak_result akp_boids_search_prepare(akp_boids_ctx* c, ak_u8_span scratch);
/* Gather agent i's neighbour sums (either path; identical results). */
void akp_boids_gather_agent(const akp_boids_ctx* c, size_t i, akp_boids_gather* g);
/* Agent i's flock neighbours sorted by (distance, index) into out[count] (count from a gather). */
void akp_boids_list_agent(const akp_boids_ctx* c, size_t i, uint32_t* out, uint32_t count);
/* Run fn(c, sorted range of the grid / agent range, user) for the step: the grid path walks
 * cells so each cell's neighbour cells are looked up once. */
typedef void (*akp_boids_agent_fn)(const akp_boids_ctx* c, size_t i, const akp_boids_gather* g, void* user);
void akp_boids_gather_range(const akp_boids_ctx* c, size_t part, size_t parts, akp_boids_agent_fn fn, void* user);
/* Split the dense layout's rows into `parts` parts (c->part_row, c->defer_row) by estimated
 * work: each row's agents times (a fixed cost per agent plus the candidates of its forward
 * rows, from the rows' agent counts); the symmetric pass needs every part but the last to hold
 * more than dim[1] rows (a row's pairs reach dim[1] + 1 rows ahead), so there are fewer
 * non-empty parts when the box has few rows; the empty ones come last. Serial: one read of
 * the rows' starts. No-op without the dense layout, or when made for these parts already
 * (akp_boids_search_prepare makes it before its fill section, whose threads also zero the
 * symmetric pass's deferred sums: akp_boids_sym_clear then has nothing left to do). */
void akp_boids_partition(akp_boids_ctx* c, size_t parts);
/* The symmetric pass (c->sym): akp_boids_partition and akp_boids_sym_clear once before the
 * threads start;
 * akp_boids_sym_range(part, parts) on each thread finds every pair once and calls fn for
 * each agent whose sums are complete; after all of them returned, akp_boids_sym_finish
 * (part, parts) calls fn for the rest (the agents of each part's deferred rows, which the part
 * before also credits), a 1/parts share of them each. */
void akp_boids_sym_clear(akp_boids_ctx* c, size_t parts);
void akp_boids_sym_range(const akp_boids_ctx* c, size_t part, size_t parts, akp_boids_agent_fn fn, void* user);
void akp_boids_sym_finish(const akp_boids_ctx* c, size_t part, size_t parts, akp_boids_agent_fn fn, void* user);

#endif
