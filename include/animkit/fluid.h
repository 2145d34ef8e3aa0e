/* animkit fluid: particle liquids, SPH and position-based fluids.
 *
 * What it does: advances a particle liquid by one time step with one of three solvers:
 *  - AK_FLUID_PBF, position-based fluids (Macklin & Mueller 2013, Algorithm 1): predict
 *    positions, find neighbours once, then `iterations` Jacobi iterations of the density
 *    constraints C_i = rho_i / rho_c - 1 (lambda_i = -C_i / (sum_k |grad_k C_i|^2 + epsilon),
 *    dp_i = (m / rho_0) sum_j (lambda_i + lambda_j + s_corr) grad W_spiky(p_i - p_j)),
 *    collision projection after each iteration, v = (x* - x) / dt, vorticity confinement and
 *    XSPH viscosity. The paper writes its equations for unit mass; here m/rho_0 multiplies the
 *    constraint gradient and the position update, so any particle mass gives the same motion.
 *    Where this reads the paper (docs/fluid.md gives the measurements):
 *     - rho_c, the density the constraint holds, is m sum_j W_poly6 over the rest lattice
 *       (1.0098 rho_0 at h = 2 spacings), the density a particle of a liquid at rest measures:
 *       a block filled at rest spacing then starts at rest instead of 1% compressed.
 *     - The constraint is unilateral by default, C_i = max(rho_i/rho_c - 1, 0): the liquid
 *       never pulls itself together, so it has no tensile instability and needs no s_corr,
 *       which is off by default (desc.scorr). desc.bilateral gives the paper's equality
 *       constraint, whose negative pressures clump particles; the paper's tensile correction
 *       s_corr = -k (W_poly6(r) / W_poly6(dq))^n, added to lambda_i + lambda_j, fights that.
 *       On a unilateral constraint s_corr is a pressure nothing balances: the liquid swells
 *       (a dam's interior fell to 0.82 rho_0). k is divided by the rest lattice's
 *       sum_k |grad_k C|^2, so k reads as "a density deficit of k" in any units; the paper's
 *       k = 0.1 belongs to its h = 0.1, rho_0 = 6378 scene units, where it means a deficit of
 *       about 16 (it throws any liquid apart), and the default is 0.01.
 *    XSPH carries the volume m / rho_j of Schechter & Bridson's form, as the paper's unit mass hides.
 *  - AK_FLUID_SPH (Mueller, Charypar, Gross 2003): density by poly6, pressure p = k (rho - rho_0),
 *    symmetric pressure force -sum_j m (p_i + p_j) / (2 rho_j) grad W_spiky, viscosity force
 *    mu sum_j m (v_j - v_i) / rho_j lap W_visc, semi-implicit Euler.
 *  - AK_FLUID_WCSPH, weakly compressible SPH (Becker & Teschner 2007): Tait equation
 *    p = B ((rho / rho_0)^gamma - 1), B = rho_0 c_s^2 / gamma, pressure acceleration
 *    -sum_j m (p_i / rho_i^2 + p_j / rho_j^2) grad W, and the paper's artificial viscosity
 *    Pi_ij = -nu (v_ij . x_ij) / (|x_ij|^2 + 0.01 h^2), nu = 2 alpha h c_s / (rho_i + rho_j),
 *    for approaching pairs, with the paper's kernel: the cubic spline (ak_fluid_cubic) for both
 *    density and gradient. (MCG's pair, poly6 density with the spiky gradient, is not the
 *    gradient of the density kernel: a column at rest needed a pressure gradient 13-30% above
 *    rho g to stand; with the cubic spline it is within 6%, see docs/fluid.md.)
 * Neighbours: each step re-sorts the particles by cell of size h (a counting sort into
 * (z, y, x) cells when the liquid's bounding box holds at most 4 cells per particle of capacity,
 * else the shared hashed grid of grid.h) and builds one list per particle, used by every pass
 * of the step; the solver works on the sorted copy (SoA positions) and writes results back in
 * the caller's order. Each list holds the particles closer than h in a fixed order (cells z,
 * then y, then x, each in index order), the same on both paths.
 *
 * Boundaries (all solvers): a box container, planes, spheres, capsules, oriented boxes,
 * convex polytopes and heightfields (so rigid bodies reach the liquid one-way:
 * ak_rigid_fluid_colliders in rigid.h), each optionally moving with a velocity and an angular
 * velocity. The method is projection: a particle found inside a collider (or outside the box)
 * is moved to the nearest surface point (a box's or a polytope's: through the face it is least
 * deep under; a heightfield's: along the normal of the triangle under it), and its velocity
 * loses only the component into the surface relative to the surface's velocity (the tangential
 * component is kept, scaled by 1 - friction). PBF projects after every Jacobi iteration, so
 * the velocity update v = (x* - x)/dt inherits the same rule. Nothing leaks (every particle ends each step
 * outside every collider and inside the box, up to float rounding of the projection; where two
 * colliders overlap, a particle in the crease between them may stay inside one: the colliders
 * are projected in turn, at most 4 passes) and
 * nothing sticks (no tangential velocity is removed unless friction > 0, and no attraction to
 * walls: boundaries add no density).
 *
 * Emitters (a nozzle disc shooting layers of particles on the rest lattice) and sinks (boxes
 * that remove particles) change the particle count; the caller owns arrays with room for the
 * largest count. Each step also flags surface particles (neighbour count below 3/4 of a full
 * lattice neighbourhood) for rendering, and can report density statistics.
 *
 * Density error (ak_fluid_stats): |rho_i / rho_0 - 1| (rho_0, not rho_c) over particles with a full
 * neighbourhood, meaning neither it nor any of its neighbours is flagged as surface, and it is
 * at least h from the box walls and every collider (particles near the free surface or a wall lack neighbours by construction).
 *
 * What it does NOT do: two-way coupling (colliders are driven, never pushed), surface tension,
 * multiple fluids, adaptive time steps, or surface reconstruction (the CLI meshes density).
 *
 * Usage:
 *     ak_fluid_desc d = {.solver = AK_FLUID_PBF, .h = 0.1f, .particle_mass = m,
 *                        .gravity = {0, -9.81f, 0}, .box_min = {0, 0, 0}, .box_max = {1, 1, 1}};
 *     size_t n = ak_fluid_fill_box(&d, lo, hi, (ak_vec3_span){pos, cap});
 *     size_t bytes = ak_fluid_scratch_size(cap, &d);
 *     void* scratch = malloc(bytes);
 *     ak_fluid_step_job job = {.desc = &d, .dt = 1.0f / 60, .positions = {pos, cap},
 *                              .velocities = {vel, cap}, .particle_count = &n,
 *                              .thread_count = 2, .scratch = {scratch, bytes}};
 *     for (int s = 0; s < steps; ++s) { job.time = s * job.dt; ak_fluid_step_run(&job); }
 *
 * Ownership and threading: jobs keep no pointer after run returns and never allocate (the
 * caller passes scratch, any alignment). thread_count threads split each phase by particle
 * (the step starts thread_count - 1 workers once, runs every phase with them, and joins them
 * before it returns; steps of fewer than 1024 particles use the caller's thread only); every
 * particle sums over its neighbours in one fixed order, so results are bit-identical
 * for any thread count. SIMD: on CPUs with AVX-512 or AVX2 (chosen at run time) the neighbour
 * filter and the density/PBF passes run 16 or 8 particles per instruction with the scalar
 * code's float operations in the same order, so results are also bit-identical to the scalar
 * kernels (job.kernels picks a set; AK_NO_SIMD builds have only the scalar one).
 */
#ifndef ANIMKIT_FLUID_H
#define ANIMKIT_FLUID_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- kernels (Mueller, Charypar, Gross 2003), 3D, support radius h ----------------- */

/* poly6: 315 / (64 pi h^9) (h^2 - r^2)^3 for r < h, else 0; takes r^2. Integrates to 1. */
AK_API float ak_fluid_poly6(float r2, float h);
/* Gradient of poly6 at offset r: -945 / (32 pi h^9) (h^2 - |r|^2)^2 r; 0 outside. */
AK_API ak_vec3 ak_fluid_poly6_grad(ak_vec3 r, float h);
/* spiky: 15 / (pi h^6) (h - r)^3 for r < h, else 0. Integrates to 1. */
AK_API float ak_fluid_spiky(float r, float h);
/* Gradient of spiky at offset r: -45 / (pi h^6) (h - |r|)^2 r / |r|; 0 at r = 0 and outside. */
AK_API ak_vec3 ak_fluid_spiky_grad(ak_vec3 r, float h);
/* viscosity kernel: 15 / (2 pi h^3) (-r^3/(2h^3) + r^2/h^2 + h/(2r) - 1) for 0 < r < h, else 0
 * (r = 0 -> 0, the kernel is singular there). Integrates to 1. */
AK_API float ak_fluid_visc(float r, float h);
/* Laplacian of the viscosity kernel: 45 / (pi h^6) (h - r) for r < h, else 0 (its integral
 * over the support is 15 / h^2: the paper's kernel is normalised through W, not its Laplacian). */
AK_API float ak_fluid_visc_laplacian(float r, float h);

/* cubic B-spline (Monaghan 1992), the WCSPH kernel of Becker & Teschner 2007, written with
 * support h (their smoothing length is h/2): with q = r/h, 8/(pi h^3) (6 (q^3 - q^2) + 1) for
 * q <= 1/2, 16/(pi h^3) (1 - q)^3 for 1/2 < q < 1, else 0. Integrates to 1. */
AK_API float ak_fluid_cubic(float r, float h);
/* Gradient of the cubic spline at offset r: W'(|r|) r / |r|, W' = 48/(pi h^4) (3 q^2 - 2 q) for
 * q <= 1/2, -48/(pi h^4) (1 - q)^2 below 1; 0 at r = 0 and outside. */
AK_API ak_vec3 ak_fluid_cubic_grad(ak_vec3 r, float h);

/* ---- description ------------------------------------------------------------------ */

typedef enum ak_fluid_solver {
    AK_FLUID_PBF = 0, /* default: position-based fluids */
    AK_FLUID_SPH,     /* MCG 2003 equation of state */
    AK_FLUID_WCSPH,   /* Becker & Teschner 2007 Tait equation */
    AK_FLUID_SOLVER_COUNT
} ak_fluid_solver;

typedef struct ak_fluid_desc {
    ak_fluid_solver solver;    /* 0 -> PBF */
    float h;                   /* required, > 0: kernel support radius (m) */
    float particle_mass;       /* required, > 0 (kg); rest spacing = cbrt(mass / rest_density) */
    float rest_density;        /* kg/m^3; 0 -> 1000 */
    ak_vec3 gravity;           /* m/s^2, world; zero = no gravity */
    /* PBF */
    uint32_t iterations;       /* Jacobi iterations per step; 0 -> 4 */
    float relaxation;          /* epsilon in 1/m^2 (|grad C|^2 units); 0 -> 0.01 * |grad C|^2 of the rest lattice */
    bool bilateral;            /* false: C_i = max(rho_i/rho_c - 1, 0) (unilateral, see above); true: the paper's C_i */
    bool scorr;                /* tensile correction s_corr (for bilateral); false = off */
    float scorr_k;             /* s_corr at r = dq as a density deficit; 0 -> 0.01 (bilateral dam, h = 2s: 0.05 and up explode) */
    float scorr_n;             /* 0 -> 4 */
    float scorr_dq;            /* |delta q| as a fraction of h; 0 -> 0.2 */
    float xsph_c;              /* XSPH coefficient; 0 = none (the paper uses 0.01) */
    float vorticity_epsilon;   /* vorticity confinement strength (m/s^2 per 1/s); 0 = none */
    /* SPH and WCSPH */
    float stiffness;           /* SPH gas constant k (J/kg); 0 -> 20 */
    float viscosity;           /* SPH mu (Pa s); WCSPH alpha (dimensionless); 0 = none */
    float sound_speed;         /* WCSPH c_s (m/s); 0 -> 20 (about 10x the speed of a 0.2 m fall) */
    float tait_gamma;          /* WCSPH gamma; 0 -> 7 */
    /* boundaries */
    ak_vec3 box_min, box_max;  /* box container (world); box_min == box_max -> no box */
    float friction;            /* 0..1: fraction of tangential velocity removed on contact; 0 = free slip */
    uint32_t max_neighbours;   /* per particle, self included; 0 -> 96; more are dropped (counted) */
} ak_fluid_desc;

/* desc with every zero default filled in (relaxation 0 -> 1% of the rest lattice's
 * sum_k |grad_k C|^2). */
AK_API ak_fluid_desc ak_fluid_desc_resolved(const ak_fluid_desc* desc);

/* Rest spacing cbrt(particle_mass / rest_density) (0 for an invalid desc). */
AK_API float ak_fluid_rest_spacing(const ak_fluid_desc* desc);

/* Positions of a cubic lattice at rest spacing filling [lo, hi] (first point at lo + s/2,
 * x fastest). Writes min(total, out_positions.count) points and returns the total. */
AK_API size_t ak_fluid_fill_box(const ak_fluid_desc* desc, ak_vec3 lo, ak_vec3 hi, ak_vec3_span out_positions);

/* ---- colliders, emitters, sinks ---------------------------------------------------- */

typedef enum ak_fluid_shape {
    AK_FLUID_PLANE = 0,   /* point a, unit normal n: the liquid stays on the +n side */
    AK_FLUID_SPHERE,      /* centre a, radius: the liquid stays outside */
    AK_FLUID_CAPSULE,     /* segment a-b, radius: the liquid stays outside (a limb) */
    AK_FLUID_BOX,         /* centre a, half_extents along the axes of orientation: the liquid stays
                             outside (a rigid box: ak_rigid_fluid_colliders) */
    AK_FLUID_CONVEX,      /* a convex polytope: the points x with n.(x') <= d for every plane
                             (n, d) of planes, x' = orientation^-1 (x - a) in the collider's frame:
                             the liquid stays outside (a rigid hull: ak_rigid_fluid_colliders) */
    AK_FLUID_HEIGHTFIELD, /* terrain, solid below its surface: heights[row * cols + col] of
                             sample (col, row) at (col * spacing, height, row * spacing) in the
                             frame (a, orientation), each cell two triangles as rigid.h's
                             heightfield (00-01-11, 00-11-10); a particle over the grid and under
                             the surface is moved out along its triangle's normal (a rigid
                             heightfield: ak_rigid_fluid_colliders) */
    AK_FLUID_SHAPE_COUNT
} ak_fluid_shape;

/* Most planes a convex collider may have. */
#define AK_FLUID_CONVEX_MAX_PLANES 65536u

typedef struct ak_fluid_collider {
    ak_fluid_shape shape; /* 0 -> plane */
    ak_vec3 a, b;         /* world: plane point / sphere centre / capsule ends / box and convex
                             frame origin */
    ak_vec3 normal;       /* plane normal (normalised by the solver; zero -> +Y) */
    float radius;         /* sphere and capsule radius (m), >= 0 */
    ak_vec3 velocity;     /* world m/s of the point a: a moving collider (the caller moves it
                             each step) */
    /* A turning collider: the surface at x moves at velocity + angular_velocity x (x - a), the
     * velocity a particle pushed out there keeps relative to (any shape; zero -> translation
     * only, as before). */
    ak_vec3 angular_velocity; /* world rad/s */
    ak_quat orientation;      /* box and convex: the frame's rotation, frame to world; zero ->
                                 identity (normalised here) */
    ak_vec3 half_extents;     /* box: metres along the frame's axes, each >= 0 */
    const ak_vec4* planes;    /* convex: (n.x, n.y, n.z, d) in the frame, n unit (within 1e-3);
                                 the liquid stays where n.x' > d for some plane */
    uint32_t plane_count;     /* convex: 1 .. AK_FLUID_CONVEX_MAX_PLANES */
    const float* heights;     /* heightfield: rows * cols finite heights (m), not copied */
    uint32_t rows, cols;      /* heightfield: >= 2 each, rows * cols <= 2^24 */
    float spacing;            /* heightfield: metres between samples, > 0 */
} ak_fluid_collider;

typedef struct ak_fluid_emitter {
    ak_vec3 position;    /* world: centre of the nozzle disc */
    ak_vec3 direction;   /* flow direction (normalised; zero -> -Y) */
    float radius;        /* nozzle radius (m), at most 4096 rest spacings; rest-lattice points inside the disc */
    float speed;         /* exit speed (m/s), > 0; one layer every spacing / speed seconds */
    float start_time;    /* s: first layer */
    float stop_time;     /* s: no layer at or after it; 0 = never stops */
} ak_fluid_emitter;

typedef struct ak_fluid_sink {
    ak_vec3 min, max; /* world box; particles inside at the end of a step are removed */
} ak_fluid_sink;

AK_DEFINE_SPAN(fluid_collider, ak_fluid_collider)
AK_DEFINE_SPAN(fluid_emitter, ak_fluid_emitter)
AK_DEFINE_SPAN(fluid_sink, ak_fluid_sink)

/* Particle flags (out_flags). */
enum { AK_FLUID_FLAG_SURFACE = 1, AK_FLUID_FLAG_FULL = 2 /* counted in the density error */ };

typedef struct ak_fluid_stats {
    float max_density_error;     /* max |rho/rho_0 - 1| over full-neighbourhood particles (0 if none) */
    float mean_density_error;    /* mean of the same (0 if none) */
    float mean_density;          /* mean rho over the same particles, kg/m^3 (0 if none) */
    float rest_lattice_density;  /* m sum_j W_poly6 over the rest lattice (kg/m^3): PBF's rho_c */
    size_t coincident_count;     /* particles closer than 1% of the rest spacing to another one
                                    when the step found neighbours (PBF: the predicted positions,
                                    already projected into the box; SPH: the step's start): a
                                    liquid collapsing onto itself or piled into a corner (a few
                                    pinned to one box edge in a healthy one) */
    size_t full_count;           /* particles counted */
    size_t surface_count;        /* particles flagged surface */
    size_t truncated_count;      /* particles with more than max_neighbours neighbours */
    size_t emitted_count;        /* added this step */
    size_t emit_dropped_count;   /* emitter particles that found no room (capacity) */
    size_t removed_count;        /* removed by sinks this step */
    float neighbour_seconds;     /* wall time of grid build + neighbour lists this step */
} ak_fluid_stats;

/* ---- the step job ------------------------------------------------------------------ */

/* Kernel sets of the neighbour filter and the density/PBF passes, chosen at run time. */
typedef enum ak_fluid_kernels {
    AK_FLUID_KERNELS_BEST = 0, /* the fastest this CPU runs */
    AK_FLUID_KERNELS_SCALAR,   /* the reference loops */
    AK_FLUID_KERNELS_AVX2,     /* 8 particles per instruction (AVX2) */
    AK_FLUID_KERNELS_AVX512,   /* 16 particles per instruction (AVX-512 F and DQ) */
    AK_FLUID_KERNELS_COUNT
} ak_fluid_kernels;

typedef struct ak_fluid_step_job {
    const ak_fluid_desc* desc;         /* required */
    float dt;                          /* required, > 0 (s) */
    float time;                        /* s: simulation time at the start of the step (emitters) */
    ak_vec3_span positions;            /* required: world m; count = capacity; [0, *particle_count) live */
    ak_vec3_span velocities;           /* required: m/s; count >= positions.count */
    size_t* particle_count;            /* required, in/out: live particles (emitters and sinks change it) */
    ak_fluid_collider_cspan colliders; /* optional */
    ak_fluid_emitter_cspan emitters;   /* optional */
    ak_fluid_sink_cspan sinks;         /* optional */
    uint32_t thread_count;             /* 0 -> 1; at most 64 */
    ak_u8_span scratch;                /* required: >= ak_fluid_scratch_size(capacity, desc) */
    ak_f32_span out_densities;         /* optional (count >= capacity): rho per particle (kg/m^3) */
    ak_f32_span out_pressures;         /* optional: pressure (Pa); PBF: -rho_0 sum_iterations lambda_i / dt^2 */
    ak_u8_span out_flags;              /* optional: AK_FLUID_FLAG_* per particle */
    ak_fluid_stats* out_stats;         /* optional */
    ak_fluid_kernels kernels;          /* 0 = the fastest this CPU runs; see ak_fluid_kernels_resolved */
} ak_fluid_step_job;

/* The kernel set a job with kernels = want runs on this CPU: BEST means the fastest, and a set
 * the CPU (or an AK_NO_SIMD build) lacks falls back to the next one down (AVX-512 -> AVX2 ->
 * scalar); out of range -> scalar. Every set gives bit-identical results (tested). */
AK_API ak_fluid_kernels ak_fluid_kernels_resolved(ak_fluid_kernels want);
/* "best", "scalar", "avx2" or "avx512". */
AK_API const char* ak_fluid_kernels_name(ak_fluid_kernels kernels);

/* Scratch bytes for up to capacity particles (0 when desc is invalid or capacity >= 2^31). */
AK_API size_t ak_fluid_scratch_size(size_t capacity, const ak_fluid_desc* desc);

/* First failing rule: AK_ERR_NULL_ARG (job, desc, particle_count, positions/velocities/scratch
 * pointers, a non-empty optional span with a NULL pointer), AK_ERR_BAD_ARG (h, mass, dt not >
 * 0 and finite, negative rest density/stiffness/viscosity/relaxation/friction > 1, solver or kernels out
 * of range, box_min > box_max, thread_count > 64, iterations > 1000, a collider shape out of
 * range or negative radius, an emitter with speed <= 0, a negative radius or one above 4096 rest
 * spacings), AK_ERR_SPAN_SMALL
 * (velocities or an optional output shorter than positions, *particle_count > capacity,
 * scratch too small), AK_ERR_BAD_DATA (a live position or velocity is NaN or infinite). */
AK_API ak_result ak_fluid_step_validate(const ak_fluid_step_job* job);

/* One time step of the chosen solver. Returns the validate codes (nothing written), AK_OK, or
 * AK_ERR_NO_CONVERGENCE when the step blew up (a position or velocity became non-finite or a
 * particle moved more than 100 h in one step): the arrays then hold that step's values and
 * the caller should stop. */
AK_API ak_result ak_fluid_step_run(const ak_fluid_step_job* job);

/* ---- scene files and presets ------------------------------------------------------------ */
/* A fluid scene: the JSON format of `animkit fluid SCENE.json` (docs/fluid.md lists every key
 * and its default) or a preset. The same loader serves C, the Python package and the command:
 *     ak_fluid_scene* sc = malloc(sizeof *sc);   // about 60 KB: the item lists are inline
 *     ak_diag diag;
 *     if (ak_fluid_scene_load_file("dam.json", sc, &diag) != AK_OK) puts(diag.message);
 *     size_t cap = ak_fluid_scene_capacity(sc), n;
 *     ... positions/velocities of cap entries; n = ak_fluid_scene_fill(sc, pos, vel, cap);
 *     ... ak_fluid_step_job job = {.desc = &sc->desc, .dt = sc->dt, .particle_count = &n,
 *             .colliders = {sc->colliders, sc->collider_count}, ...}; run
 *         ak_fluid_scene_steps(sc) steps of ak_fluid_step_run, job.time = k * sc->dt. */

/* Budgets that bound a hostile scene's memory (checked before anything is allocated). */
#define AK_FLUID_SCENE_MAX_PARTICLES 2000000u
#define AK_FLUID_SCENE_MAX_ITEMS 256u     /* blocks, colliders, emitters, sinks each */
#define AK_FLUID_SCENE_MAX_STEPS 10000000L
#define AK_FLUID_SCENE_MAX_FILE_SIZE ((size_t)64 << 20)
/* The names ak_fluid_scene_preset knows. */
#define AK_FLUID_SCENE_PRESETS "dam, pour, splash"

/* An initial block of liquid: the rest lattice filling [min, max], moving at velocity. */
typedef struct ak_fluid_block {
    ak_vec3 min, max, velocity;
} ak_fluid_block;

/* A loaded scene (no pointers: copy it freely). */
typedef struct ak_fluid_scene {
    ak_fluid_desc desc;    /* h = h_ratio * rest spacing */
    float h_ratio;         /* default 2 */
    float dt;              /* default 1/400 (PBF), 1e-3 (SPH) or 2e-4 (WCSPH) */
    float duration;        /* simulated seconds when steps is not given; default 1 */
    long steps;            /* default (-1): ceil(duration / dt), see ak_fluid_scene_steps */
    long max_particles;    /* capacity; default: initial particles + 20000 when emitters exist */
    size_t block_count, collider_count, emitter_count, sink_count;
    ak_fluid_block blocks[AK_FLUID_SCENE_MAX_ITEMS];
    ak_fluid_collider colliders[AK_FLUID_SCENE_MAX_ITEMS];
    ak_fluid_emitter emitters[AK_FLUID_SCENE_MAX_ITEMS];
    ak_fluid_sink sinks[AK_FLUID_SCENE_MAX_ITEMS];
    bool dt_set;           /* "dt" was given (else dt follows the solver) */
} ak_fluid_scene;

/* The defaults of every key: PBF, 1 cm particles of water, gravity -9.81 Y, no box, nothing else. */
AK_API void ak_fluid_scene_defaults(ak_fluid_scene* scene);
/* Parse a scene from bytes[0, size) (strict JSON); name (NULL -> "(scene)") starts every
 * message. Counts and sizes are checked against the budgets above (the initial particle count
 * included). Returns AK_OK, or AK_ERR_PARSE / AK_ERR_NULL_ARG with *out_scene at its defaults
 * and, when out_diag is not NULL, the one line "NAME: key.path: problem" in out_diag->message. */
AK_API ak_result ak_fluid_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                           ak_fluid_scene* out_scene, ak_diag* out_diag);
/* Read the file at path (at most AK_FLUID_SCENE_MAX_FILE_SIZE bytes) and parse it; AK_ERR_IO
 * when it cannot be read ("PATH: cannot open the file"). */
AK_API ak_result ak_fluid_scene_load_file(const char* path, ak_fluid_scene* out_scene, ak_diag* out_diag);
/* The preset name (AK_FLUID_SCENE_PRESETS) of about count particles (<= 0 -> 4000; at most
 * AK_FLUID_SCENE_MAX_PARTICLES). AK_ERR_NOT_FOUND for another name. */
AK_API ak_result ak_fluid_scene_preset(const char* name, long count, ak_fluid_scene* out_scene,
                                       ak_diag* out_diag);
/* A fluid scene owns no memory: this resets it to the defaults (NULL: no-op); it exists so every
 * scene type has the same life cycle. */
AK_API void ak_fluid_scene_free(ak_fluid_scene* scene);
/* The default step of a solver: 1/400 s (PBF), 1e-3 s (SPH), 2e-4 s (WCSPH). */
AK_API float ak_fluid_scene_default_dt(ak_fluid_solver solver);
/* The steps to run: scene->steps when >= 0, else ceil(duration / dt) (1 to AK_FLUID_SCENE_MAX_STEPS). */
AK_API long ak_fluid_scene_steps(const ak_fluid_scene* scene);
/* Particles the blocks hold (their lattice points). */
AK_API size_t ak_fluid_scene_initial_count(const ak_fluid_scene* scene);
/* The capacity to allocate: max_particles when given, else the initial count (+ 20000 with emitters). */
AK_API size_t ak_fluid_scene_capacity(const ak_fluid_scene* scene);
/* Fill positions/velocities (capacity entries at most) with the blocks' particles; returns the count. */
AK_API size_t ak_fluid_scene_fill(const ak_fluid_scene* scene, ak_vec3* positions, ak_vec3* velocities,
                                  size_t capacity);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_FLUID_H */
