/* animkit boids: Reynolds flocking (1987) with vision, topological neighbours, obstacles and
 * predators, for crowds of a million agents.
 *
 * What it does:
 *   - one step job that moves N agents (caller-owned SoA arrays: positions, velocities,
 *     species) by the three rules of Reynolds 1987, each with a weight and a radius:
 *       separation  F_s = w_s * sum_j (p_i - p_j) / |p_i - p_j|^2   (inverse-distance repulsion)
 *       alignment   F_a = w_a * (mean_j v_j - v_i)                    (steer to the mean velocity)
 *       cohesion    F_c = w_c * (mean_j p_j - p_i)                    (steer to the centroid)
 *     where j runs over the agent's neighbours closer than that rule's radius. Neighbours are
 *     agents of the same species, other than i, with |p_j - p_i| < the largest of the three
 *     radii AND inside the field-of-view cone (view_angle degrees around the velocity), then
 *     optionally capped to the k nearest (topological neighbours; ties broken by the smaller
 *     agent index). Exactly, in float: d = p_j - p_i, d2 = d.x*d.x + d.y*d.y + d.z*d.z, a rule
 *     uses j when d2 < radius*radius; with c = cos(view_angle/2), dot = d . v_i, lim =
 *     c*c * d2 * |v_i|^2, j is in view when (c >= 0) dot > 0 && dot*dot >= lim, (c < 0)
 *     dot >= 0 || dot*dot <= lim, and always when |v_i| = 0 or d2 = 0. The separation
 *     distance is clamped below at 1e-3 separation_radius (coincident agents push nothing);
 *   - extensions, each a weighted steering force: obstacle avoidance (spheres, planes,
 *     axis-aligned boxes) with a hard projection as the last resort so that no agent ever
 *     enters an obstacle, bounds (wrap or steer back), goal seeking, leader following, flee
 *     from predators and pursue prey (species with their own parameters), per-agent wander
 *     from a seeded ak_rng; 2D (agents on a horizontal plane) and 3D;
 *   - the neighbour search through a uniform grid, and the naive O(N^2) loop as the reference
 *     path (job.use_naive): both give exactly the same neighbour sets and bit-identical steps;
 *   - the neighbour lists themselves (ak_boids_neighbors_run), the flocking order parameter and
 *     the smallest distance between two agents.
 *
 * Integration (per agent, semi-implicit Euler): F = sum of the weighted forces, its length
 * clamped to max_force; v' = v + F dt, its length clamped to [min_speed, max_speed] (the
 * clamps scale the vector, keeping its direction); p' = p + v' dt; then the bounds wrap (a
 * coordinate that left the box comes back by whole box widths: one, for a step shorter than
 * the box) and the obstacle projection (below). In 2D (params.planar) every force and
 * velocity has y = 0 and agents keep their y; the neighbour distance still includes y.
 *
 * Obstacles: the avoid force steers away before contact; the hard projection is the last
 * resort and always runs: a step whose segment p -> p' would enter an obstacle (or end inside
 * one) stops at the entry point, is pushed 1e-5 m (+ 4e-7 relative) outside along the surface
 * normal, and loses the inward part of its velocity (out_contact_count counts these agents).
 * An agent the caller placed inside leaves by the nearest face. Overlapping obstacles are
 * resolved by up to four passes; agents therefore end every step at distance >= 0 from every
 * obstacle (tests check this on spheres, planes and boxes in 2D and 3D).
 *
 * Determinism: each agent's sums are accumulated in 64-bit fixed point (2^-28 of the
 * cohesion radius for offsets, of max_speed for velocities; 2^-24 of 1/separation_radius for
 * separation), which is exact and so independent of the order neighbours are visited in.
 * Any thread_count, the grid and the naive path give bit-identical results.
 *
 * What it does NOT do: rendering (the `animkit boids` command draws flocks with raster.h),
 * collisions between agents (separation only steers), neighbours across a wrapping bound (the
 * wrap moves agents; neighbours use the plain Euclidean distance), or vision occlusion.
 *
 * Usage:
 *     ak_boids_species sp = {.max_speed = 2, .max_force = 8, .separation_weight = 1,
 *                            .alignment_weight = 1, .cohesion_weight = 0.5f, .view_angle = 270};
 *     ak_boids_params params = {.species = &sp, .species_count = 1};
 *     ak_boids_step_job job = {
 *         .params = &params, .dt = 1.0f / 60.0f, .thread_count = 2,
 *         .positions = {pos, n}, .velocities = {vel, n},
 *         .out_positions = {pos2, n}, .out_velocities = {vel2, n},
 *     };
 *     size_t bytes = ak_boids_step_scratch_size(&job);   // once for a given n and params
 *     job.scratch = (ak_u8_span){malloc(bytes), bytes};
 *     for (int s = 0; s < steps; ++s) {
 *         job.step_index = (uint64_t)s;
 *         ak_result r = ak_boids_step_run(&job);          // then swap pos/pos2, vel/vel2 (and
 *     }                                                   // the job's pointers) for the next step
 *
 * Ownership and threading: the job reads and writes caller-owned arrays and keeps no pointer.
 * ak_boids_step_run never allocates (thread_count > 1 starts pthreads: runs of cell rows of
 * about equal estimated work per thread; the bits do not depend on the thread count). Outputs must not alias inputs (the wander state is updated in place: each agent
 * touches only its own entry).
 *
 * Speed (docs/boids.md, docs/BENCHMARKS.md): agents re-sorted by cell; for one species that
 * only flocks, each pair's distance test runs once and credits both agents (each with its own
 * view cone); AVX-512 kernels chosen at run time (job.skip_simd forces the scalar/SSE2 code,
 * which gives the same bits).
 */
#ifndef ANIMKIT_BOIDS_H
#define ANIMKIT_BOIDS_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AK_BOIDS_MAX_SPECIES 32 /* species indices are < this (flee/pursue masks are 32 bits) */
#define AK_BOIDS_MAX_K 64       /* largest k_nearest */
#define AK_BOIDS_MAX_AGENTS 100000000u /* largest agent_count a job accepts */

/* Parameters of one species. Weights are accelerations (m/s^2 per unit of the rule's vector):
 * a zero weight switches its rule off. */
typedef struct ak_boids_species {
    float max_speed;         /* m/s; 0 -> 2 */
    float min_speed;         /* m/s, <= max_speed; 0 -> none (agents may stop) */
    float max_force;         /* m/s^2, clamp on the summed steering; 0 -> 8 */
    float separation_weight; /* m^2/s^2: F_s = w * sum (p_i - p_j)/d^2; 0 -> off */
    float separation_radius; /* m; 0 -> 1 */
    float alignment_weight;  /* 1/s: F_a = w * (mean v_j - v_i); 0 -> off */
    float alignment_radius;  /* m; 0 -> 2 */
    float cohesion_weight;   /* 1/s^2: F_c = w * (mean p_j - p_i); 0 -> off */
    float cohesion_radius;   /* m; 0 -> 2 */
    float view_angle;        /* degrees, full cone angle around the velocity; 0 or >= 360 -> all
                                around. An agent at rest sees all around. */
    uint32_t k_nearest;      /* cap on neighbours (the k nearest); 0 -> no cap; <= AK_BOIDS_MAX_K */
    float goal_weight;       /* 1/s: seek params.goal (desired velocity max_speed toward it); 0 -> off */
    float leader_weight;     /* 1/s: seek the point leader_distance behind the leader; 0 -> off */
    float wander_weight;     /* m/s^2: force along the agent's wander direction; 0 -> off */
    float wander_jitter;     /* radians per sqrt(second) of random walk of that direction; 0 -> 2 */
    float avoid_weight;      /* m/s^2: F = w * (L - s)/s * n within avoid_distance L of an
                                obstacle (s = distance, n = outward normal); 0 -> off */
    float avoid_distance;    /* m: L above; 0 -> 1 */
    float bounds_weight;     /* 1/s^2: STEER bounds pull back with w * (depth into the margin); 0 -> 4 */
    uint32_t flee_mask;      /* bit s set: flee from the nearest agent of species s */
    float flee_weight;       /* 1/s: desired velocity max_speed away from it; 0 -> off */
    float flee_radius;       /* m: only predators closer than this; 0 -> 4 */
    uint32_t pursue_mask;    /* bit s set: pursue the nearest agent of species s */
    float pursue_weight;     /* 1/s: desired velocity max_speed toward its predicted position */
    float pursue_radius;     /* m: only prey closer than this; 0 -> 4 */
} ak_boids_species;

typedef enum ak_boids_obstacle_kind {
    AK_BOIDS_SPHERE = 0, /* center, radius */
    AK_BOIDS_PLANE,      /* solid half-space behind the plane through center: dot(n, x - c) < 0 */
    AK_BOIDS_BOX,        /* axis-aligned box: center, half_extents */
    AK_BOIDS_OBSTACLE_KIND_COUNT
} ak_boids_obstacle_kind;

/* A solid obstacle; agents are points and stay outside (distance >= 0). In 2D each obstacle
 * is cut at the agent's height (a sphere becomes a disc of the same radius, a plane's normal
 * loses its y). */
typedef struct ak_boids_obstacle {
    ak_boids_obstacle_kind kind;
    ak_vec3 center;       /* world m */
    float radius;         /* m, sphere (> 0) */
    ak_vec3 normal;       /* plane: outward normal (normalised by the job; non-zero) */
    ak_vec3 half_extents; /* m, box (each > 0) */
} ak_boids_obstacle;

typedef enum ak_boids_bounds {
    AK_BOIDS_BOUNDS_DEFAULT = 0, /* -> STEER when a box is given, else NONE */
    AK_BOIDS_BOUNDS_NONE,        /* the box is ignored */
    AK_BOIDS_BOUNDS_STEER,       /* inside the margin, agents are pulled back (force, not a wall) */
    AK_BOIDS_BOUNDS_WRAP,        /* leaving one side re-enters from the opposite side */
    AK_BOIDS_BOUNDS_COUNT
} ak_boids_bounds;

/* What the agents share: species table, obstacles, bounds, goal, leader. */
typedef struct ak_boids_params {
    const ak_boids_species* species;     /* required: [species_count] */
    uint32_t species_count;              /* 1 ..= AK_BOIDS_MAX_SPECIES */
    const ak_boids_obstacle* obstacles;  /* optional: [obstacle_count] */
    uint32_t obstacle_count;             /* <= 1024 */
    ak_vec3 bounds_min, bounds_max;      /* world m; all zero -> no box; else max > min */
    ak_boids_bounds bounds;              /* see ak_boids_bounds */
    float bounds_margin;                 /* m, STEER: width of the band that pulls back; 0 -> 1 */
    bool planar;                         /* 2D: forces and velocities in the XZ plane */
    ak_vec3 goal;                        /* world m, for species with goal_weight */
    bool has_leader;                     /* leader following on (species with leader_weight) */
    uint32_t leader_index;               /* the leader agent (< agent_count when has_leader) */
    float leader_distance;               /* m behind the leader that followers seek; 0 -> 1 */
} ak_boids_params;

/* A species with every zero default filled in (NULL -> all defaults); for tests and tools. */
AK_API void ak_boids_species_resolved(const ak_boids_species* species, ak_boids_species* out_species);

/* ---- the step job --------------------------------------------------------------------- */

typedef struct ak_boids_step_job {
    const ak_boids_params* params;   /* required */
    ak_vec3_cspan positions;         /* required: [agent_count] world m; count = agent_count */
    ak_vec3_cspan velocities;        /* required: >= agent_count, m/s */
    ak_u8_cspan species;             /* optional: >= agent_count species indices; empty -> all 0 */
    ak_vec3_span wander;             /* in/out state, required when a species wanders: unit
                                        directions (zero entries are re-drawn), >= agent_count */
    float dt;                        /* s, required: > 0 */
    uint64_t seed;                   /* wander random stream (ak_rng per agent and step) */
    uint64_t step_index;             /* wander: pass the step number so each step draws anew */
    uint32_t thread_count;           /* 0 or 1 -> calling thread; <= 64 */
    bool use_naive;                  /* the O(N^2) reference neighbour search (no scratch) */
    ak_u8_span scratch;              /* >= ak_boids_step_scratch_size(job) bytes */
    ak_vec3_span out_positions;      /* >= agent_count; must not alias the inputs */
    ak_vec3_span out_velocities;     /* >= agent_count; must not alias the inputs */
    uint64_t* out_interaction_count; /* optional: flock neighbours summed over all agents */
    uint32_t* out_contact_count;     /* optional: agents the obstacle projection had to stop */
    bool skip_simd;                  /* false -> fastest kernels for this CPU; true -> the
                                        scalar/SSE2 code (same results, bit for bit: tests) */
    bool skip_avx512;                /* true -> the AVX2 kernel where AVX-512 would run (same
                                        results: tests, benchmarks); false -> fastest */
    uint64_t max_cell_load;          /* work budget of the grid path: sum over the grid's cells
                                        of (agents in the cell)^2; 0 -> AK_BOIDS_DEFAULT_CELL_LOAD */
} ak_boids_step_job;

/* The grid path's cost is about (2 rings + 1)^3 / 2 distance tests per unit of cell load
 * (sum over cells of n_c^2, cells as large as the largest rule radius, so rings = 1): a flock
 * at the usual density (about 8 agents per cell) has a load of about 8 per agent, 100,000
 * agents at one point have 1e10 (a quadratic step of hours). Above max_cell_load the step
 * returns AK_ERR_BUDGET and writes nothing; the default, 2e7, passes flocks of a few million
 * agents at the usual density and about 4,500 agents stacked in one cell. The naive path
 * (use_naive) has no budget: it is quadratic by definition. */
#define AK_BOIDS_DEFAULT_CELL_LOAD 20000000u

/* Scratch bytes ak_boids_step_run needs for this job (positions.count, params and use_naive
 * are read; 0 for the naive path, and 0 when no species looks at neighbours). The grid path
 * needs about 140 bytes per agent (the grid, the agents re-sorted by cell, velocities in fixed
 * point, a cell table), plus 96 when one species only flocks (no k cap, flee or pursue: the
 * neighbour sums of the symmetric pair pass).
 * Returns 0 when the job's params are unusable (validate says why). */
AK_API size_t ak_boids_step_scratch_size(const ak_boids_step_job* job);

/* Check a step job. Returns, in this order: AK_ERR_NULL_ARG (no job, params, species, arrays
 * or outputs; a wandering species without the wander span; obstacle_count > 0 without
 * obstacles), AK_ERR_BAD_ARG (dt not > 0 or not finite, species_count outside 1..32,
 * thread_count > 64, more than AK_BOIDS_MAX_AGENTS agents or 1024 obstacles, bounds not
 * max > min on every axis (y is free in 2D), leader_index out of range, a species parameter
 * negative or not finite, k_nearest > AK_BOIDS_MAX_K, min_speed > max_speed, a bad obstacle:
 * radius or half extent not > 0, zero plane normal, unknown kind; outputs aliasing inputs),
 * AK_ERR_EMPTY (no agents), AK_ERR_SPAN_SMALL (an array shorter than agent_count, scratch
 * too small), AK_ERR_BAD_INDEX (a species index >= species_count), AK_ERR_BAD_DATA (a NaN or
 * infinite position, velocity or wander entry, or coordinates beyond 1e15 m). */
AK_API ak_result ak_boids_step_validate(const ak_boids_step_job* job);

/* One step for every agent (see the header block). Validates first and writes nothing on
 * failure (from 65,536 agents on, the O(n) check of the agents' data runs on the step's
 * threads; the result is the one ak_boids_step_validate gives). Output is finite for valid
 * input. Besides the validation codes: AK_ERR_BUDGET when
 * the agents are packed so densely that the grid's cell load exceeds max_cell_load (above). */
AK_API ak_result ak_boids_step_run(const ak_boids_step_job* job);

/* ---- neighbour lists ------------------------------------------------------------------ */

/* The flock neighbours each agent's rules use (same species, radius, view cone, k cap), as
 * compressed rows: agent i's neighbours are out_indices[out_offsets[i] .. out_offsets[i+1]),
 * sorted by distance, ties by index. Same inputs as the step job (params, positions,
 * velocities, species, thread_count, use_naive, scratch as for the step job); dt, wander and
 * the step outputs are not read. */
typedef struct ak_boids_neighbors_job {
    const ak_boids_step_job* step;   /* required: the inputs above */
    ak_u32_span out_offsets;         /* >= agent_count + 1 */
    ak_u32_span out_indices;         /* capacity; see out_total */
    size_t* out_total;               /* required: neighbours in all (written even when the
                                        indices span is too small, then AK_ERR_SPAN_SMALL) */
} ak_boids_neighbors_job;

/* Fill the neighbour lists. Returns the step job's validation codes (dt is not checked),
 * AK_ERR_BUDGET as the step (the step job's max_cell_load),
 * AK_ERR_NULL_ARG (no out_total or offsets), AK_ERR_SPAN_SMALL (offsets shorter than
 * agent_count + 1, or out_indices shorter than the total: then out_total holds the count
 * needed and the offsets are written). */
AK_API ak_result ak_boids_neighbors_run(const ak_boids_neighbors_job* job);

/* ---- measures ------------------------------------------------------------------------- */

/* Flocking order parameter |mean of v_i / |v_i||, in [0, 1] (1: all agents head the same
 * way). Agents at rest count as zero vectors. Empty span -> 0. Summed in double. */
AK_API float ak_boids_order(ak_vec3_cspan velocities);

/* Bytes of scratch ak_boids_min_distance needs for count agents. */
AK_API size_t ak_boids_min_distance_scratch_size(size_t count);

/* Smallest distance between two agents (exact: a sort on x and a sweep, O(N log N) for
 * spread-out agents). Fewer than two agents -> AK_ERR_EMPTY. Returns AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL (scratch), AK_ERR_BAD_DATA (non-finite position). */
AK_API ak_result ak_boids_min_distance(ak_vec3_cspan positions, ak_u8_span scratch, float* out_distance);

/* Name of the grid-path kernels ak_boids_step_run uses on this CPU (chosen at run time):
 * "avx512" (AVX-512 F+DQ distance filter and, for one species, neighbour rules and the
 * integration), "avx2" (SSE2 filter, AVX2 symmetric pair kernel), "sse2" or "scalar"
 * (AK_NO_SIMD builds). Every kernel gives bit-identical results. */
AK_API const char* ak_boids_simd_name(void);

/* ---- scene files and presets ------------------------------------------------------------ */
/* A boids scene: the JSON format of `animkit boids SCENE.json` (docs/boids.md lists every key,
 * its default and its range) or a preset, over the defaults:
 *     ak_boids_scene sc;
 *     ak_diag diag;
 *     ak_boids_scene_defaults(&sc);                          // or ak_boids_scene_preset(...)
 *     if (ak_boids_scene_load_file("flock.json", &sc, &diag) != AK_OK) puts(diag.message);
 *     if (sc.agent_count == 0) ak_boids_scene_scale_bounds(&sc, sc.count);
 *     ... ak_boids_* with sc.params, sc.steps steps of sc.dt; sc.agent_count agents from the
 *         file (sc.positions...), else sc.count placed at random (seed sc.seed) ...
 *     ak_boids_scene_free(&sc); */

#define AK_BOIDS_SCENE_MAX_AGENTS 10000000u /* agents in a file or asked for by count */
#define AK_BOIDS_SCENE_MAX_OBSTACLES 1024u
#define AK_BOIDS_SCENE_MAX_FILE_SIZE ((size_t)64 << 20)
/* The names ak_boids_scene_preset knows. */
#define AK_BOIDS_SCENE_PRESETS "flock, obstacles, predator"
/* Agents the default 20 m box is sized for (ak_boids_scene_scale_bounds). */
#define AK_BOIDS_SCENE_BOX_AGENTS 500u

/* A loaded scene; it owns obstacles, positions, velocities and agent_species (malloc). */
typedef struct ak_boids_scene {
    ak_boids_species species[AK_BOIDS_MAX_SPECIES];
    float fraction[AK_BOIDS_MAX_SPECIES]; /* share of the random agents (species 0 takes the rest) */
    ak_vec4 color[AK_BOIDS_MAX_SPECIES];  /* sRGB body colour when rendering */
    ak_boids_obstacle* obstacles;         /* [params.obstacle_count] */
    ak_boids_params params;               /* points into species / obstacles */
    ak_vec3* positions;                   /* [agent_count] from "agents", or NULL */
    ak_vec3* velocities;
    uint8_t* agent_species;
    size_t agent_count;                   /* 0: place `count` agents at random */
    size_t count;                         /* random agents; default 500 */
    long steps;                           /* default 2000 */
    float dt;                             /* default 0.02 */
    long seed;                            /* default 1 */
    float shape_size;                     /* metres, length of a rendered bird */
    int shape;                            /* 0 bird, 1 fish */
    bool bounds_given;                    /* the scene set bounds.min or bounds.max */
} ak_boids_scene;

/* The defaults of every key (the scene without a file); owns nothing. */
AK_API void ak_boids_scene_defaults(ak_boids_scene* scene);
/* Parse bytes[0, size) (strict JSON) OVER the scene already in *scene, which must hold
 * ak_boids_scene_defaults or a preset (keys absent from the file keep its values); name (NULL ->
 * "(scene)") starts every message. Returns AK_OK, or AK_ERR_PARSE / AK_ERR_NULL_ARG with, when
 * out_diag is not NULL, the one line "NAME: key.path: problem" in out_diag->message. In every case
 * *scene owns its arrays afterwards: free it with ak_boids_scene_free. */
AK_API ak_result ak_boids_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                           ak_boids_scene* scene, ak_diag* out_diag);
/* Read the file at path (at most AK_BOIDS_SCENE_MAX_FILE_SIZE bytes) and parse it over *scene as
 * ak_boids_scene_load_bytes does; AK_ERR_IO when it cannot be read. */
AK_API ak_result ak_boids_scene_load_file(const char* path, ak_boids_scene* scene, ak_diag* out_diag);
/* The defaults, then the preset name (AK_BOIDS_SCENE_PRESETS): "flock" (the defaults themselves),
 * "obstacles" (a sphere and four pillars in the flock's way) or "predator" (a second species,
 * 0.6% of the agents, that chases the flock, which flees). *out_scene is overwritten without
 * being freed (pass a new or freed scene). AK_ERR_NOT_FOUND for another name, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_boids_scene_preset(const char* name, ak_boids_scene* out_scene, ak_diag* out_diag);
/* Free the arrays (NULL: no-op; safe twice). */
AK_API void ak_boids_scene_free(ak_boids_scene* scene);
/* The default box for count random agents (call after count and planar are final, only when the
 * scene lists no agents): unless the scene set bounds.min or bounds.max, the 20 m box of the
 * defaults grows beyond AK_BOIDS_SCENE_BOX_AGENTS agents by cbrt(count / AK_BOIDS_SCENE_BOX_AGENTS)
 * on every axis (sqrt when planar), so the density, and the neighbours per agent, stay those of
 * 500 agents. */
AK_API void ak_boids_scene_scale_bounds(ak_boids_scene* scene, size_t count);

/* ---- running a scene ---------------------------------------------------------------------- */
/* Step a loaded scene as `animkit boids` does, so that C and Python reproduce the command's
 * output: the scene's agents, or scene->count agents placed at random in the bounds from
 * scene->seed (species by fraction, speed half the species' max_speed), double-buffered steps
 * whose wander noise follows the step number.
 *     ak_boids_scene_run run;
 *     if (ak_boids_scene_run_init(&run, &sc, NULL, &diag) == AK_OK)
 *         for (long k = 0; k < sc.steps && ak_boids_scene_run_step(&run) == AK_OK; ++k) {}
 *     ... run.positions[i], run.velocities[i] for i < run.agent_count ...
 *     ak_boids_scene_run_free(&run); */
typedef struct ak_boids_scene_run_desc {
    const char* name;      /* starts messages; NULL -> "scene" */
    uint32_t thread_count; /* 0 -> 1 */
    bool naive;            /* the O(N^2) neighbour search instead of the grid (same results) */
} ak_boids_scene_run_desc;

typedef struct ak_boids_scene_run {
    size_t agent_count;
    ak_vec3* positions;    /* [agent_count]: the current state (swapped each step) */
    ak_vec3* velocities;
    uint8_t* species;
    long step_index;       /* steps taken */
    ak_boids_step_job job; /* points into the scene's params and the arrays below */
    /* private */
    size_t n;
    ak_vec3 *p, *v, *p2, *v2, *w;
    uint8_t* s;
    uint8_t* scratch;
    size_t scratch_size;
} ak_boids_scene_run;

/* Place the agents and validate the step job. The scene must outlive the run. AK_OK, or the
 * failing code with "NAME: problem" in out_diag; free with ak_boids_scene_run_free either way. */
AK_API ak_result ak_boids_scene_run_init(ak_boids_scene_run* run, const ak_boids_scene* scene,
                                         const ak_boids_scene_run_desc* desc, ak_diag* out_diag);
/* One step (number run->step_index). AK_ERR_BUDGET: agents packed past the grid's work budget
 * (ak_boids_scene_run_error says what to lower). */
AK_API ak_result ak_boids_scene_run_step(ak_boids_scene_run* run);
/* What a failed step's result means for a user. */
AK_API const char* ak_boids_scene_run_error(ak_result result);
/* Free the arrays (safe on a zeroed or failed run, and twice). */
AK_API void ak_boids_scene_run_free(ak_boids_scene_run* run);

#ifdef __cplusplus
}
#endif

#endif
