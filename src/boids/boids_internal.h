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

/* Per-step context: the job, resolved species, the search state. */
typedef struct akp_boids_ctx {
    const ak_boids_step_job* job;
    const ak_boids_params* params;
    size_t n;
    ak_boids_bounds bounds; /* resolved mode */
    akp_boids_sp sp[AK_BOIDS_MAX_SPECIES];
    float search_radius;    /* largest query radius over species (0: nobody looks) */
    /* Grid path (use_naive false). */
    ak_grid grid;
    int rings;              /* cells visited on each side of an agent's cell */
    const int64_t* sqv;     /* [3n] velocities in sorted order, fixed point (alignment sums) */
    const uint8_t* ssp;     /* [n] species in sorted order */
    /* Dense cell table over the occupied cells' bounding box (when it is small enough): cell
     * (x, y, z) -> grid cell index m or UINT32_MAX, so a neighbour cell costs one load instead
     * of a hash probe, and cells can be walked in spatial order. NULL when not built. */
    uint32_t* dense;
    int32_t dense_min[3];
    int32_t dense_dim[3];
} akp_boids_ctx;

/* What one agent gathers from its neighbours. */
typedef struct akp_boids_gather {
    const akp_boids_sp* sp;
    uint32_t i;                    /* the agent (original index) */
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

/* search.c */
size_t akp_boids_search_scratch_size(const ak_boids_step_job* job);
/* Build the grid (unless use_naive) into scratch. */
ak_result akp_boids_search_prepare(akp_boids_ctx* c, ak_u8_span scratch);
/* Gather agent i's neighbour sums (either path; identical results). */
void akp_boids_gather_agent(const akp_boids_ctx* c, size_t i, akp_boids_gather* g);
/* Agent i's flock neighbours sorted by (distance, index) into out[count] (count from a gather). */
void akp_boids_list_agent(const akp_boids_ctx* c, size_t i, uint32_t* out, uint32_t count);
/* Run fn(c, sorted range of the grid / agent range, user) for the step: the grid path walks
 * cells so each cell's neighbour cells are looked up once. */
typedef void (*akp_boids_agent_fn)(const akp_boids_ctx* c, size_t i, const akp_boids_gather* g, void* user);
void akp_boids_gather_range(const akp_boids_ctx* c, size_t part, size_t parts, akp_boids_agent_fn fn, void* user);

#endif
