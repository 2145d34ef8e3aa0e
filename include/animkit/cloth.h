/* animkit cloth: mass-spring and XPBD cloth, pinned or attached to animated characters.
 *
 * What it does:
 *   - a cloth is a triangle mesh (a generated W x H rectangle of particles, or any triangle mesh,
 *     plus optional extra edges) with per-vertex mass; particles can be pinned at fixed points
 *     or attached to target positions the caller gives every step (a skinned mesh's vertices or
 *     joints), so a cape, skirt or flag follows an animated character;
 *   - four solvers over the same cloth:
 *       AK_CLOTH_XPBD (default): extended position-based dynamics (Macklin, Mueller, Chentanez
 *         2016): distance constraints with compliance alpha = 1/stiffness, alpha~ = alpha/h^2,
 *         the Lagrange multipliers reset at the start of every substep, dihedral-angle or
 *         isometric bending (or bending distance constraints), constraint
 *         damping (their eq. 26), substeps of h = dt/substeps with `iterations` Gauss-Seidel
 *         sweeps each; optional long-range attachments (Kim, Chentanez, Mueller 2012);
 *       AK_CLOTH_SPRINGS: the classic mass-spring model: structural, shear and bending springs
 *         (Hooke plus damping along the spring), semi-implicit (symplectic) Euler, v += h a,
 *         x += h v; stable only for h below about 2 sqrt(m/k), so it needs small steps
 *         (ak_cloth_stable_substep says how small);
 *       AK_CLOTH_IMPLICIT: the same springs under implicit (backward) Euler, linearised once per
 *         substep and solved by conjugate gradients (Baraff & Witkin 1998): (M + h D + h^2 K) dv
 *         = h (f + h (df/dx) v) with K = -df/dx, D = -df/dv assembled from the springs (the
 *         transverse stiffness of a compressed spring clamped at zero so the system stays
 *         positive definite), Jacobi-preconditioned CG in double with the pinned and attached
 *         particles' velocity changes fixed by a filter (their modified CG); stable at any
 *         step, with numerical damping that grows with h; on the calling thread only;
 *       AK_CLOTH_PBD: plain position-based dynamics (Mueller et al. 2007): the same constraints
 *         projected with a per-projection stiffness factor in (0, 1]; its effective stiffness
 *         depends on the substep and iteration counts (the problem XPBD solves);
 *   - forces: gravity, wind (drag and lift per triangle from its orientation to the relative
 *     wind), global damping;
 *   - collisions with planes, spheres, capsules (a character's limbs) and a triangle mesh (the
 *     character's skin, through a spatial hash rebuilt each step), with thickness and friction;
 *   - self-collision between particles through the shared neighbour grid (grid.h), switchable;
 *   - smooth (area-weighted) vertex normals, max stretch and energy for output and tests;
 *   - precision: a step integrates each particle's displacement since the step's start and
 *     reads vectors between particles as their start-of-step value plus the displacements'
 *     difference, so a substep's motion keeps float precision at any substep count and
 *     distance from the origin; optional position_residuals keep what float positions lose;
 *   - thread_count: threads split each phase over disjoint particles or over constraints of one
 *     colour (constraints of a colour share no particle), so results are bit-identical for any
 *     thread count; small cloths run on fewer threads than asked (see thread_count);
 *   - SIMD: the XPBD/PBD constraint solves run 16 (AVX-512F) or 8 (AVX2) constraints of a colour
 *     at a time, chosen at run time, with the scalar path's exact bits (see ak_cloth_simd).
 *
 * What it does NOT do: continuous collision detection (a particle moving
 * further than the thickness in one substep can tunnel through a thin collider), tearing,
 * or moving the colliders inside a step (they are taken at their end-of-step pose).
 *
 * Usage (a flag pinned along one edge, flapping in the wind):
 *     ak_cloth_desc desc = { .grid_width = 32, .grid_height = 20, .spacing = 0.05f,
 *                            .grid_axis_v = {0, -1, 0} };
 *     uint32_t pins[2] = {0, 32 * 19};                     // the two corners of the pole edge
 *     desc.pins = (ak_u32_cspan)AK_SPAN(pins);
 *     ak_cloth* cloth = NULL;
 *     if (ak_cloth_create(&desc, NULL, &cloth) != AK_OK) return 1;
 *     size_t n = ak_cloth_vertex_count(cloth);
 *     ak_vec3* x = malloc(n * sizeof *x); ak_vec3* v = calloc(n, sizeof *v);
 *     ak_cloth_rest_positions(cloth, (ak_vec3_span){x, n});
 *     ak_cloth_step_job job = { .cloth = cloth, .dt = 1.0f / 60, .gravity = {0, -9.81f, 0},
 *                               .wind = {6, 0, 1}, .drag = 1.0f, .lift = 0.5f,
 *                               .positions = {x, n}, .velocities = {v, n} };
 *     size_t size = ak_cloth_step_scratch_size(&job);
 *     job.scratch = (ak_u8_span){malloc(size), size};
 *     for (int f = 0; f < 600; ++f) if (ak_cloth_step_run(&job) != AK_OK) break;
 *     ak_cloth_destroy(cloth);
 *
 * Ownership and threading: ak_cloth_create makes one allocation holding the topology, the
 * rest state and the coloured constraints; the cloth is then read-only and may be shared by any
 * number of threads. The state (positions, velocities) and scratch belong to the caller.
 * ak_cloth_step_run never allocates memory of its own (thread_count > 1 starts pthreads for
 * the duration of the call, whose stacks the C library allocates). Steps of distinct states
 * may run concurrently.
 */
#ifndef ANIMKIT_CLOTH_H
#define ANIMKIT_CLOTH_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ak_cloth_solver {
    AK_CLOTH_XPBD = 0,   /* default: compliant constraints, substeps */
    AK_CLOTH_SPRINGS,    /* mass-spring, semi-implicit Euler */
    AK_CLOTH_PBD,        /* plain PBD with a stiffness factor (for comparison) */
    AK_CLOTH_IMPLICIT,   /* mass-spring, implicit (backward) Euler (Baraff & Witkin 1998) */
    AK_CLOTH_SOLVER_COUNT
} ak_cloth_solver;

typedef enum ak_cloth_bending {
    AK_CLOTH_BEND_DEFAULT = 0, /* -> DIHEDRAL for XPBD and PBD; the spring solvers (SPRINGS,
                                  IMPLICIT) always use SPRINGS (or NONE) */
    AK_CLOTH_BEND_DIHEDRAL,    /* angle between the two triangles of each interior edge */
    AK_CLOTH_BEND_SPRINGS,     /* distance between the wing vertices of each interior edge (grid:
                                  particles two apart along each axis) */
    AK_CLOTH_BEND_NONE,        /* no bending resistance */
    AK_CLOTH_BEND_ISOMETRIC,   /* isometric bending (Bergou et al. 2006): the cotangent-weighted
                                  bending vector b = sum_i K_i x_i of each interior edge's four
                                  particles, energy 3 k |b|^2 / (2 (A0 + A1)), as one XPBD/PBD
                                  constraint C = |b| - |b_rest| (exact for a flat rest shape);
                                  about a third of the dihedral constraint's cost */
    AK_CLOTH_BENDING_COUNT
} ak_cloth_bending;

typedef struct ak_cloth_desc {
    ak_cloth_solver solver;      /* 0 -> AK_CLOTH_XPBD */
    /* Topology: a generated grid when positions is empty, else the given mesh. */
    uint32_t grid_width;         /* grid: particles along grid_axis_u, >= 2 (required for a grid) */
    uint32_t grid_height;        /* grid: particles along grid_axis_v, >= 2 (required for a grid) */
    float spacing;               /* grid: metres between neighbours; 0 -> 0.05 */
    ak_vec3 grid_origin;         /* grid: world position of particle (0, 0), index 0 */
    ak_vec3 grid_axis_u;         /* grid: direction of rows (normalised); zero -> (1, 0, 0) */
    ak_vec3 grid_axis_v;         /* grid: direction of columns (normalised); zero -> (0, 0, -1)
                                    (a horizontal sheet whose triangles face +Y: they face
                                    u x v). Particle (i, j) has index j * grid_width + i */
    ak_vec3_cspan positions;     /* mesh: rest positions (world); empty -> grid */
    ak_u32_cspan indices;        /* mesh: 3 per triangle, counter-clockwise (may be empty with edges) */
    ak_u32_cspan edges;          /* optional: 2 per extra stretch spring/constraint (ropes, the
                                    single-spring test), in grid or mesh */
    ak_f32_cspan inverse_masses; /* optional: 1/kg per vertex, >= 0 (0 = pinned); empty -> from
                                    area_density (a third of each triangle's mass per corner) */
    float area_density;          /* kg/m^2 when inverse_masses is empty; 0 -> 0.2 */
    ak_u32_cspan pins;           /* vertices held at pin_positions (or their rest positions) */
    ak_vec3_cspan pin_positions; /* optional: one per pin, world; empty -> rest positions */
    ak_u32_cspan attachments;    /* vertices that follow ak_cloth_step_job.attachment_targets */
    /* Material. Spring constants apply to every spring of the kind whatever its length. */
    float stretch_stiffness;     /* N/m of structural springs/constraints (XPBD compliance is its
                                    inverse; INFINITY -> rigid, compliance 0, XPBD/PBD only);
                                    0 -> 5000 */
    float shear_stiffness;       /* N/m of grid diagonals; 0 -> stretch_stiffness */
    float bend_stiffness;        /* N/m of bending springs; 0 -> stretch_stiffness / 100 */
    float dihedral_stiffness;    /* bending modulus k of dihedral bending (N m/rad: energy k theta^2 / 2,
                                    XPBD compliance 1/k) and of isometric bending (N m); 0 -> 1e-4
                                    (cotton-like: a draped sheet folds) */
    ak_cloth_bending bending;    /* 0 -> see ak_cloth_bending */
    float spring_damping;        /* SPRINGS, IMPLICIT: N s/m along each spring; 0 -> none */
    float constraint_damping;    /* XPBD: beta (s) of the paper's eq. 26, stiffness-proportional
                                    damping; 0 -> none */
    float pbd_stiffness;         /* PBD: factor (0, 1] applied to each projection; 0 -> 1 */
    bool long_range_attachments; /* XPBD/PBD: each free particle stays within (1 + slack) times
                                    its rest distance of its nearest pinned or attached particle */
    float long_range_slack;      /* fraction of extra length allowed; 0 -> exactly the rest distance */
} ak_cloth_desc;

/* The desc with zero defaults filled in (desc NULL -> every default; the topology spans and
 * the grid size are copied, not checked). */
AK_API ak_cloth_desc ak_cloth_desc_resolved(const ak_cloth_desc* desc);

typedef struct ak_cloth ak_cloth;

/* Build a cloth: topology, masses, constraints (coloured so that one colour touches each
 * particle at most once). Returns AK_ERR_NULL_ARG (desc or out_cloth NULL), AK_ERR_EMPTY (no
 * grid and no positions, or no triangle and no edge), AK_ERR_BAD_ARG (grid side < 2, grid over
 * 2^24 particles, unknown solver or bending, negative or NaN stiffness, damping, density, slack,
 * pbd_stiffness > 1, infinite stiffness with a spring solver, indices or edges not a multiple
 * of 3 or 2, pin_positions count != pins count, an allocator with only one function, a vertex on
 * no triangle whose mass must come from area_density), AK_ERR_BAD_INDEX (an index, edge, pin or
 * attachment out of range, an edge or triangle with a repeated vertex, a vertex both pinned and
 * attached or listed twice), AK_ERR_BAD_DATA (a non-finite position, pin position or inverse
 * mass, or a negative inverse mass), AK_ERR_NO_MEMORY. *out_cloth is NULL on failure. */
AK_API ak_result ak_cloth_create(const ak_cloth_desc* desc, const ak_allocator* alloc, ak_cloth** out_cloth);
/* Free a cloth; NULL is a no-op. */
AK_API void ak_cloth_destroy(ak_cloth* cloth);

/* Queries (a NULL cloth gives 0 or empty spans). */
AK_API size_t ak_cloth_vertex_count(const ak_cloth* cloth);
AK_API size_t ak_cloth_triangle_count(const ak_cloth* cloth);
/* The triangles (3 indices each): the grid's or a copy of the desc's. */
AK_API ak_u32_cspan ak_cloth_indices(const ak_cloth* cloth);
/* Inverse mass per vertex after pins and attachments (those are 0). */
AK_API ak_f32_cspan ak_cloth_inverse_masses(const ak_cloth* cloth);
/* Number of attachments (the count attachment_targets must have). */
AK_API size_t ak_cloth_attachment_count(const ak_cloth* cloth);
/* The desc the cloth was built with, resolved. Its indices, inverse_masses (after pins and
 * attachments), pins, pin_positions and attachments point at the cloth's own arrays; positions
 * and edges are not kept (empty spans; ak_cloth_rest_positions gives the rest state). */
AK_API ak_cloth_desc ak_cloth_get_desc(const ak_cloth* cloth);

/* Rest positions, with pinned vertices at their pin positions, into out_positions
 * (count >= vertex count). Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_cloth_rest_positions(const ak_cloth* cloth, ak_vec3_span out_positions);

/* Largest stable substep h (seconds) of the spring solver for this cloth: the mass-spring
 * system's linearisation at rest, x'' = -M^-1 K x - M^-1 D x', under semi-implicit Euler is
 * stable while h^2 omega^2 + 2 h gamma < 4, with omega^2 and gamma bounded (Gershgorin on
 * M^-1/2 K M^-1/2, and on D) by
 *     omega^2 <= max_i sum_{springs s = (i, j)} k_s (w_i + sqrt(w_i w_j)),
 *     gamma   <= max_i sum_{springs s = (i, j)} c   (w_i + sqrt(w_i w_j))
 * over the free particles i (w = 1/m the inverse masses, k_s the spring's stiffness, c =
 * spring_damping): h = (sqrt(gamma^2 + 4 omega^2) - gamma) / omega^2, i.e. 2 / omega without
 * damping. The stiffest springs on the lightest particle decide it. Substeps of dt / h or more
 * keep the spring solver stable (a stretched spring's transverse stiffness stays below k; wind
 * drag is not counted). INFINITY for the other solvers (unconditionally stable) and for a
 * cloth without springs on a free particle; 0 for a NULL cloth. */
AK_API float ak_cloth_stable_substep(const ak_cloth* cloth);

/* ---- colliders ------------------------------------------------------------------------ */

typedef struct ak_cloth_plane {
    ak_vec3 normal; /* world, normalised here; points to the free side; zero -> (0, 1, 0) */
    float offset;   /* the plane is dot(normal, x) = offset */
} ak_cloth_plane;

typedef struct ak_cloth_sphere {
    ak_vec3 center; /* world */
    float radius;   /* metres, >= 0 */
} ak_cloth_sphere;

typedef struct ak_cloth_capsule {
    ak_vec3 a, b;   /* world: the segment's ends (a == b -> a sphere) */
    float radius;   /* metres, >= 0 */
} ak_cloth_capsule;

/* A closed, outward-facing triangle mesh (counter-clockwise seen from outside), e.g. a skinned
 * character at this step's pose. Particles closer than the thickness in front of a triangle, or
 * up to two thicknesses behind it, are pushed out along the triangle's normal. */
typedef struct ak_cloth_collider_mesh {
    ak_vec3_cspan positions; /* world; empty -> no mesh collider */
    ak_u32_cspan indices;    /* 3 per triangle */
} ak_cloth_collider_mesh;

/* ---- stepping ------------------------------------------------------------------------- */

/* Upper limit on the SIMD width the XPBD/PBD constraint solves may use (the widest this CPU
 * has up to the limit is used; tests and benchmarks run every path side by side with it).
 * Every path gives the scalar code's bits: the same float operations in the same order, no
 * fused multiply-add. The mass-spring solver and the other phases are scalar. */
typedef enum ak_cloth_simd {
    AK_CLOTH_SIMD_DEFAULT = 0, /* -> the widest this CPU has (AK_CLOTH_SIMD_AVX512) */
    AK_CLOTH_SIMD_SCALAR,      /* one constraint at a time */
    AK_CLOTH_SIMD_AVX2,        /* 8 constraints of a colour per block, where the CPU has AVX2 */
    AK_CLOTH_SIMD_AVX512,      /* 16 per block where the CPU has AVX-512F, else AVX2 */
    AK_CLOTH_SIMD_COUNT
} ak_cloth_simd;

/* Advance the cloth by dt. Positions and velocities are the caller's state (in and out). */
typedef struct ak_cloth_step_job {
    const ak_cloth* cloth;         /* required */
    float dt;                      /* seconds, > 0 (required) */
    uint32_t substeps;             /* h = dt / substeps; 0 -> 10 */
    uint32_t iterations;           /* XPBD/PBD Gauss-Seidel sweeps per substep; 0 -> 1. IMPLICIT: the
                                      most conjugate-gradient iterations per substep; 0 -> 100
                                      (it stops earlier once the preconditioned residual falls
                                      below 1e-3 of the right-hand side's) */
    ak_vec3 gravity;               /* m/s^2, world; zero -> none */
    ak_vec3 wind;                  /* m/s, world air velocity; zero -> still air */
    float drag;                    /* drag coefficient C_d per triangle; 0 -> no drag */
    float lift;                    /* lift coefficient C_l per triangle; 0 -> no lift */
    float air_density;             /* kg/m^3; 0 -> 1.2 */
    float damping;                 /* 1/s: velocities decay by exp(-damping h) per substep; 0 -> none */
    const ak_cloth_plane* planes;  /* plane_count entries */
    size_t plane_count;
    const ak_cloth_sphere* spheres; /* sphere_count entries */
    size_t sphere_count;
    const ak_cloth_capsule* capsules; /* capsule_count entries */
    size_t capsule_count;
    ak_cloth_collider_mesh mesh;   /* optional character mesh */
    float thickness;               /* metres kept between particles and colliders; 0 -> 0.01 */
    float friction;                /* Coulomb coefficient at contacts, >= 0; 0 -> frictionless */
    bool self_collision;           /* true -> particles keep self_distance apart (pairs closer at
                                      rest keep their rest distance), found each substep through
                                      the shared neighbour grid (grid.h), resolved Jacobi-style
                                      (each particle moves by the mean of its pair corrections,
                                      at most 32 neighbours) */
    float self_distance;           /* metres; 0 -> 2 * thickness */
    ak_vec3_cspan attachment_targets; /* world, one per attachment (required when the cloth has
                                         attachments): where the attached particles are at the end
                                         of this step; substeps move them linearly from where
                                         they are */
    uint32_t thread_count;         /* 0 or 1 -> the calling thread only; at most 64. An upper
                                      bound: XPBD/PBD use at most one thread per 8192 constraints
                                      in an average colour (the threads meet after each colour;
                                      smaller shares cost more in meetings than they save), so a
                                      64 x 64 cloth runs on one thread, 256 x 256 on up to 2 */
    bool exact_thread_count;       /* false -> the rule above; true -> thread_count threads
                                      whatever the cloth's size (tests, measurements) */
    ak_cloth_simd simd_limit;      /* 0 -> the widest constraint solve this CPU has; else at most
                                      this one (out of range: AK_ERR_BAD_ARG) */
    ak_vec3_span positions;        /* required, count == vertex count: in and out */
    ak_vec3_span velocities;       /* required, count == vertex count: in and out */
    ak_vec3_span position_residuals; /* optional, count == vertex count, in and out (start them at
                                      zero): what a float position cannot hold, so that
                                      positions + residuals carry about 48 bits. Far from the
                                      origin (1 km: float spacing 6e-5 m) a step otherwise rounds
                                      every position once; with residuals the motion is the
                                      same as near the origin. Empty -> rounded (velocities
                                      are kept as integrated either way) */
    ak_vec3_span out_normals;      /* optional, count >= vertex count: smooth normals after the step */
    ak_u8_span scratch;            /* required, size >= ak_cloth_step_scratch_size(job) */
} ak_cloth_step_job;

/* Scratch bytes a step needs (depends on the cloth and the collider mesh's triangle count);
 * 0 when job or job->cloth is NULL. */
AK_API size_t ak_cloth_step_scratch_size(const ak_cloth_step_job* job);

/* First failing rule: AK_ERR_NULL_ARG (job, cloth, positions, velocities or scratch empty, a
 * collider count without its array, attachments without targets), AK_ERR_BAD_ARG (dt <= 0 or
 * non-finite, position_residuals count != vertex count when given, thread_count > 64, substeps or iterations > 10000, simd_limit out of range, negative or non-finite drag,
 * lift, air density, damping, thickness, friction or self_distance, a negative radius, collider mesh indices
 * not a multiple of 3, positions/velocities count != vertex count, attachment_targets count !=
 * attachment count), AK_ERR_SPAN_SMALL (out_normals or scratch too small), AK_ERR_BAD_INDEX (a
 * collider mesh index out of range), AK_ERR_BAD_DATA (a non-finite position, velocity,
 * gravity, wind, collider, target or residual). A zero-initialised job gives AK_ERR_NULL_ARG. */
AK_API ak_result ak_cloth_step_validate(const ak_cloth_step_job* job);
/* Validate, then step (writes nothing on a validation failure; the per-vertex data checks run
 * on the step's threads, before anything is written). Returns
 * AK_ERR_NO_CONVERGENCE when the state became non-finite (a blow-up: the spring solver with too
 * large a step); the state then holds the non-finite values, so keep a copy to go back to. */
AK_API ak_result ak_cloth_step_run(const ak_cloth_step_job* job);

/* Name of the widest constraint solve ak_cloth_step_run can use on this CPU: "avx512", "avx2"
 * or "scalar" (AK_NO_SIMD builds: "scalar"). */
AK_API const char* ak_cloth_simd_name(void);

/* ---- measures ------------------------------------------------------------------------- */

/* Smooth vertex normals (area-weighted sum of the triangle normals, normalised; vertices on no
 * triangle get (0, 1, 0)). positions.count == vertex count, out_normals.count >= vertex count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_cloth_normals(const ak_cloth* cloth, ak_vec3_cspan positions, ak_vec3_span out_normals);

/* Largest (edge length / rest length - 1) over the structural constraints (mesh edges, grid rows
 * and columns, extra edges); 0 for a cloth without any; NaN when a position is not finite. */
AK_API float ak_cloth_max_stretch(const ak_cloth* cloth, ak_vec3_cspan positions);

typedef struct ak_cloth_energy {
    double kinetic;   /* J: sum of m |v|^2 / 2 over free particles */
    double potential; /* J: sum of -m gravity . x over free particles (zero at the origin) */
    double elastic;   /* J: sum of k C^2 / 2 over the springs/constraints (dihedral: the angle) */
    double total;     /* kinetic + potential + elastic */
} ak_cloth_energy;

/* Energy of a state (double precision). positions and velocities: count == vertex count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG. */
AK_API ak_result ak_cloth_energy_compute(const ak_cloth* cloth, ak_vec3_cspan positions, ak_vec3_cspan velocities,
                                         ak_vec3 gravity, ak_cloth_energy* out_energy);

/* ---- scene files and presets ------------------------------------------------------------ */
/* A cloth scene: the JSON format of `animkit cloth SCENE.json` (docs/cloth.md lists every key,
 * its unit and its default) or a preset, parsed into one struct that owns its arrays. A scene
 * may name a character (character.model: a file or builtin:NAME, and attachments to its joints
 * or skinned vertices): the loader only records the names; loading and posing the model is the
 * caller's (animkit/io.h; the command does it in tools/animkit/cloth_run.c).
 *     ak_cloth_scene sc;
 *     ak_diag diag;
 *     if (ak_cloth_scene_preset("flag", &sc, &diag) != AK_OK) puts(diag.message);
 *     ak_cloth* cloth; ak_cloth_create(&sc.desc, NULL, &cloth);   // desc's spans point into sc
 *     ... step sc.steps times with sc.dt, sc.substeps, sc.gravity, sc.wind, the colliders ...
 *     ak_cloth_scene_free(&sc); */

/* Budgets: a scene file cannot ask for more than this. */
#define AK_CLOTH_SCENE_MAX_PARTICLES ((size_t)1 << 20)
#define AK_CLOTH_SCENE_MAX_LIST 4096 /* pins, attachments, colliders of each kind */
#define AK_CLOTH_SCENE_MAX_STEPS 1000000L
#define AK_CLOTH_SCENE_MAX_FILE_SIZE ((size_t)64 << 20)
/* The names ak_cloth_scene_preset knows. */
#define AK_CLOTH_SCENE_PRESETS "flag, curtain, drape, cape"

/* A cloth vertex held by the character. */
typedef struct ak_cloth_attach_spec {
    uint32_t vertex;     /* cloth vertex */
    char joint[64];      /* follow this joint rigidly ("" -> mesh_vertex) */
    long mesh_vertex;    /* or follow this skinned vertex of the character's mesh 0 (-1: joint) */
    bool has_position;   /* position given: the vertex starts there (else at its rest position) */
    ak_vec3 position;    /* world, at t = 0: where the attachment holds it (gathers a collar) */
} ak_cloth_attach_spec;

/* A loaded scene (free with ak_cloth_scene_free). */
typedef struct ak_cloth_scene {
    ak_cloth_desc desc;        /* grid, material, solver (spans point into the arrays below) */
    uint32_t* pins;            /* [pin_count] */
    size_t pin_count;
    ak_vec3* pin_positions;    /* [pin_position_count]: 0 (rest positions) or pin_count */
    size_t pin_position_count;
    ak_cloth_attach_spec* attach; /* [attach_count] */
    size_t attach_count;
    /* stepping */
    float dt;                  /* seconds per step; default 1/60 */
    long steps;                /* default 120 */
    uint32_t substeps, iterations; /* defaults 10, 1 */
    bool iterations_given;     /* the scene says "iterations" (else implicit uses its own cap) */
    bool substeps_forced;      /* set by the caller (the command's --substeps): the spring solver
                                  keeps it even below its stable count (else runs at least that) */
    ak_vec3 gravity, wind;
    float gust;                /* wind *= 1 + gust * sin(2 pi gust_frequency t) */
    float gust_frequency;
    float drag, lift, air_density, damping, thickness, friction, self_distance;
    bool self_collision;
    ak_cloth_plane* planes;
    size_t plane_count;
    ak_cloth_sphere* spheres;
    size_t sphere_count;
    ak_cloth_capsule* capsules;
    size_t capsule_count;
    /* character (recorded only, see above) */
    char model[256];           /* "" -> none; else FILE or builtin:NAME */
    char clip[64];             /* clip name or index; "" -> the first */
    bool mesh_collider;        /* the posed character mesh collides */
    bool limb_capsules;        /* capsules along the character's bones collide */
    float capsule_scale;       /* limb capsule radius / mean skin distance to the bone */
    int thread_count;          /* default 1 */
} ak_cloth_scene;

/* The defaults of every key (no arrays). */
AK_API void ak_cloth_scene_defaults(ak_cloth_scene* scene);
/* Parse a scene from bytes[0, size) (strict JSON); name (NULL -> "scene") starts every message.
 * Returns AK_OK, or AK_ERR_PARSE / AK_ERR_NULL_ARG with *out_scene at its defaults (no arrays)
 * and, when out_diag is not NULL, the one line "NAME: key.path: problem" in out_diag->message. */
AK_API ak_result ak_cloth_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                           ak_cloth_scene* out_scene, ak_diag* out_diag);
/* Read the file at path (at most AK_CLOTH_SCENE_MAX_FILE_SIZE bytes) and parse it; AK_ERR_IO
 * when it cannot be read ("PATH: cannot open the file"). */
AK_API ak_result ak_cloth_scene_load_file(const char* path, ak_cloth_scene* out_scene, ak_diag* out_diag);
/* The preset name (AK_CLOTH_SCENE_PRESETS; docs/cloth.md describes them). AK_ERR_NOT_FOUND for
 * another name, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_cloth_scene_preset(const char* name, ak_cloth_scene* out_scene, ak_diag* out_diag);
/* Free the scene's arrays (NULL: no-op; safe on a failed or freed scene). */
AK_API void ak_cloth_scene_free(ak_cloth_scene* scene);

/* ---- running a scene ---------------------------------------------------------------------- */
/* Step a loaded scene as `animkit cloth` does, so that C and Python reproduce the command's
 * output: the cloth built from scene->desc, the spring solver raised to its stable substep count
 * (unless scene->substeps_forced), gusty wind (wind x (1 + gust sin(2 pi gust_frequency t))),
 * the scene's colliders. A scene with a character (scene->model) needs the caller: it loads and
 * poses the model, passes the posed mesh and the number of its limb capsules here, and before
 * each step writes run->targets (attachment targets at the step's end) and the capsules after
 * the scene's (run->capsules[scene->capsule_count + k]); tools/animkit/cloth_run.c does so.
 *     ak_cloth_scene_run run;
 *     if (ak_cloth_scene_run_init(&run, &sc, NULL, &diag) == AK_OK)
 *         for (long k = 0; k < sc.steps && ak_cloth_scene_run_step(&run, "flag", &diag) == AK_OK; ++k) {}
 *     ... run.positions[i] for i < run.vertex_count ...
 *     ak_cloth_scene_run_free(&run); */
typedef struct ak_cloth_scene_run_desc {
    const char* name;                /* starts messages; NULL -> "scene" */
    size_t extra_capsule_count;      /* capsules after the scene's that the caller sets each step */
    ak_cloth_collider_mesh mesh;     /* optional: a collider mesh the caller poses between steps */
} ak_cloth_scene_run_desc;

typedef struct ak_cloth_scene_run {
    ak_cloth_scene* scene;           /* the scene run (its substeps may be raised, see above) */
    ak_cloth* cloth;
    ak_vec3* positions;              /* [vertex_count], stepped in place */
    ak_vec3* velocities;
    ak_vec3* normals;
    ak_vec3* targets;                /* [scene->attach_count]: the caller's, before each step */
    ak_cloth_capsule* capsules;      /* the scene's, then desc.extra_capsule_count of the caller's */
    size_t vertex_count;
    long step_index;                 /* steps taken */
    float time;                      /* simulated seconds */
    double stable_substep;           /* > 0 when the spring solver raised the substeps: its bound (s) */
    uint32_t substeps_given;         /* ... the count the scene asked for */
    double substeps_needed;          /* ... and the count it needs */
    ak_cloth_step_job job;           /* points into the arrays above and the scene */
    /* private */
    ak_vec3* residuals;
    uint8_t* scratch;
    uint32_t* attach_idx;
} ak_cloth_scene_run;

/* Build the cloth and its step job. The scene must outlive the run. AK_OK, or the failing code
 * with "NAME: problem" in out_diag (AK_ERR_BUDGET: the spring solver needs over 10000 substeps);
 * free with ak_cloth_scene_run_free either way. */
AK_API ak_result ak_cloth_scene_run_init(ak_cloth_scene_run* run, ak_cloth_scene* scene,
                                         const ak_cloth_scene_run_desc* desc, ak_diag* out_diag);
/* One step with the gust of the step's start. AK_ERR_NO_CONVERGENCE: a blow-up ("NAME: blow-up:
 * the state became non-finite at step K ..."); other codes name the step. name NULL -> "scene". */
AK_API ak_result ak_cloth_scene_run_step(ak_cloth_scene_run* run, const char* name, ak_diag* out_diag);
/* Free the run (safe on a zeroed or failed run, and twice). */
AK_API void ak_cloth_scene_run_free(ak_cloth_scene_run* run);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_CLOTH_H */
