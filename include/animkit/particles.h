/* animkit particles: particle systems (Reeves 1983): emit, push, integrate, collide, expire.
 *
 * What it does: a particle system of fixed capacity holds its state as structure-of-arrays
 * (position, velocity, force accumulator, inverse mass with 0 = pinned, age, lifetime, size,
 * colour, id). Emitters add particles from a point, a sphere (volume or surface), a disc, a
 * box or the surface of a triangle mesh (area-weighted, e.g. a posed skinned character),
 * at a rate per second with fractional carry-over (2.5/s emits exactly 5 in 2 s) or in
 * bursts, with velocities in a cone, a speed range and a lifetime range, all drawn from the
 * system's one seeded ak_rng. A step applies forces (gravity, linear and quadratic drag
 * relative to the wind, point attractors/repulsors with softening, vortices, damped springs,
 * Lennard-Jones between all pairs within a cut-off through the neighbour grid of grid.h, and
 * a caller callback), integrates with the system's integrator, collides with planes,
 * spheres, boxes and triangle meshes (restitution and Coulomb friction), ages particles and
 * removes the dead.
 *
 * Integrators (ak_particles_integrator):
 *   EULER       explicit Euler, order 1: x += dt v(t); v += dt a(t). Gains energy on
 *               oscillators; only for teaching and comparisons.
 *   SYMPLECTIC  semi-implicit Euler, order 1: v += dt a(t); x += dt v(t+dt). One force
 *               evaluation, energy stays bounded on springs: the default for effects.
 *   VERLET      velocity Verlet, order 2: x += dt v + dt^2/2 a; v += dt/2 (a + a(t+dt)), the
 *               second force evaluation using the predicted velocity v + dt a for
 *               velocity-dependent forces. Symplectic for position-only forces; exact for
 *               constant acceleration. Pick it for stiff springs and orbits.
 *   RK4         classic Runge-Kutta, order 4, four force evaluations: accurate smooth
 *               trajectories (not symplectic: slowly loses energy on oscillators).
 * Collisions run after the integration of each step on the segment from the old to the new
 * position, so a plane or sphere cannot be tunnelled through within a step.
 * The semi-implicit step of a world with only gravity, drag, wind and planes (the common
 * effects case) runs fused SIMD blocks (AVX2 when the CPU has it, else SSE2; scalar with
 * AK_NO_SIMD) that round exactly as the scalar path does.
 *
 * Dead particles (age >= lifetime) are removed at the end of the step that kills them by a
 * stable compaction: survivors keep their relative order, so the indices of particles after
 * a dead one move down (the particles before it keep theirs). Particles added with infinite
 * lifetime before any emitted ones therefore keep their indices forever (springs refer to
 * indices: point them at such particles). The id array follows each particle.
 *
 * What it does NOT do: rigid bodies, particle-particle collisions (use Lennard-Jones for
 * repulsion), implicit integration, or rendering (the CLI draws with raster.h; ak_particle_look
 * describes colour, size and sprite frame over a particle's life for a renderer).
 *
 * Usage:
 *     ak_particles* ps;
 *     ak_particles_create(&(ak_particles_desc){.capacity = 10000, .seed = 1}, NULL, &ps);
 *     ak_particle_emitter fountain = {.shape = AK_EMITTER_POINT, .rate = 500,
 *         .direction = {0, 1, 0}, .cone_angle = 0.3f, .speed_min = 4, .speed_max = 5,
 *         .lifetime_min = 2, .lifetime_max = 3};
 *     ak_particle_plane floor = {.normal = {0, 1, 0}, .restitution = 0.5f, .friction = 0.2f};
 *     ak_particles_world world = {.gravity = {0, -9.81f, 0}, .planes = {&floor, 1}};
 *     for (int s = 0; s < 100; ++s) {
 *         ak_particles_emit(ps, &fountain, 0.01f, NULL);
 *         ak_particles_step(ps, &world, 0.01f);
 *     }
 *     ak_particles_state st = ak_particles_get_state(ps);  // st.position[0 .. st.count)
 *     ak_particles_destroy(ps);
 *
 * Ownership and threading: a system is one allocation (create/destroy); the world, emitters
 * and colliders are the caller's and are only read during a call (an emitter's carry field
 * is written). A step splits particles over thread_count threads; results are bit-identical
 * for any thread count (each particle's arithmetic does not depend on the split; springs and
 * the callback run on the calling thread in a fixed order). A system must not be used from
 * two threads at once; different systems may.
 */
#ifndef ANIMKIT_PARTICLES_H
#define ANIMKIT_PARTICLES_H

#include "grid.h"
#include "raster.h" /* ak_blend, ak_sprite_texture: a scene's "render" settings */

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ak_particles_integrator {
    AK_INTEGRATOR_DEFAULT = 0, /* -> AK_INTEGRATOR_SYMPLECTIC */
    AK_INTEGRATOR_EULER,
    AK_INTEGRATOR_SYMPLECTIC,
    AK_INTEGRATOR_VERLET,
    AK_INTEGRATOR_RK4,
    AK_INTEGRATOR_COUNT
} ak_particles_integrator;

typedef struct ak_particles_desc {
    uint32_t capacity;                  /* required, 1 .. 2^30: most particles alive at once */
    ak_particles_integrator integrator; /* 0 -> SYMPLECTIC */
    uint64_t seed;                      /* seed of the system's ak_rng (every value valid) */
    uint32_t thread_count;              /* 0 -> 1; at most 64 */
} ak_particles_desc;

typedef struct ak_particles ak_particles;

/* The live state, SoA, count entries each; pointers into the system (valid until destroy).
 * The caller may edit values in place between calls (e.g. move pinned particles). */
typedef struct ak_particles_state {
    size_t count;
    ak_vec3* position; /* world space, metres */
    ak_vec3* velocity; /* metres per second */
    ak_vec3* force;    /* newtons: the pair, spring and callback forces of the last evaluation */
    float* inv_mass;   /* 1/kg; 0 = pinned (never moved by the step) */
    float* age;        /* seconds since emission */
    float* lifetime;   /* seconds; INFINITY = never dies */
    float* size;       /* radius for rendering, metres (collisions treat particles as points) */
    ak_vec4* colour;   /* linear RGBA */
    uint32_t* id;      /* unique per system, in order of addition */
} ak_particles_state;

/* The desc with its zero fields replaced by their defaults (integrator, thread_count);
 * NULL -> all defaults (capacity stays 0, which create rejects). */
AK_API ak_particles_desc ak_particles_desc_resolved(const ak_particles_desc* desc);

/* Create an empty system. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (capacity 0 or above 2^30,
 * integrator out of range, thread_count > 64), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_particles_create(const ak_particles_desc* desc, const ak_allocator* alloc,
                                     ak_particles** out_particles);
/* NULL is a no-op. */
AK_API void ak_particles_destroy(ak_particles* particles);

/* The live arrays (count entries each; zeros for NULL). Valid until the next call that adds
 * or removes particles moves them (emit, burst, add, step, clear) or destroy. */
AK_API ak_particles_state ak_particles_get_state(ak_particles* particles);
/* Particles alive now (0 for NULL). */
AK_API size_t ak_particles_count(const ak_particles* particles);
/* The capacity fixed at creation (0 for NULL). */
AK_API size_t ak_particles_capacity(const ak_particles* particles);
/* Seconds simulated so far (sum of the steps' dt, in double; 0 for NULL). */
AK_API double ak_particles_time(const ak_particles* particles);
/* Change the integrator between steps (DEFAULT -> SYMPLECTIC). AK_ERR_NULL_ARG,
 * AK_ERR_BAD_ARG when out of range. */
AK_API ak_result ak_particles_set_integrator(ak_particles* particles,
                                             ak_particles_integrator integrator);

/* One particle to add by hand. */
typedef struct ak_particle_init {
    ak_vec3 position;
    ak_vec3 velocity;
    float mass;     /* kg; 0 = pinned (inverse mass 0) */
    float lifetime; /* seconds; 0 -> INFINITY */
    float size;     /* metres; 0 -> 0.05 */
    ak_vec4 colour; /* all zero -> opaque white */
} ak_particle_init;

/* Append a particle; *out_index (optional) gets its index. AK_ERR_SPAN_SMALL when the
 * system is full, AK_ERR_BAD_DATA for non-finite values or a negative mass/lifetime. */
AK_API ak_result ak_particles_add(ak_particles* particles, const ak_particle_init* init,
                                  size_t* out_index);

/* Remove every particle (time, ids and the rng go on). NULL is a no-op. */
AK_API void ak_particles_clear(ak_particles* particles);

/* ---- emitters ----------------------------------------------------------------------- */

typedef enum ak_emitter_shape {
    AK_EMITTER_POINT = 0,      /* at center */
    AK_EMITTER_SPHERE,         /* uniform in the ball of radius around center */
    AK_EMITTER_SPHERE_SURFACE, /* uniform on the sphere */
    AK_EMITTER_DISC,           /* uniform on the disc of radius around center, facing direction */
    AK_EMITTER_BOX,            /* uniform in center +- half_extents */
    AK_EMITTER_MESH,           /* uniform over the area of a triangle mesh (see mesh_*), 1e-4 m out
                                  along the triangle's normal (counter-clockwise front) */
    AK_EMITTER_SHAPE_COUNT
} ak_emitter_shape;

typedef struct ak_particle_emitter {
    ak_emitter_shape shape; /* 0 -> POINT */
    ak_vec3 center;         /* world space */
    float radius;           /* SPHERE, SPHERE_SURFACE, DISC: metres (0 = a point) */
    ak_vec3 half_extents;   /* BOX: metres */
    ak_vec3 direction;      /* cone axis (normalised here); zero -> +Y. MESH: the triangle
                               normal is the axis unless use_direction_on_mesh */
    bool use_direction_on_mesh; /* MESH: false -> the cone axis is each triangle's normal */
    float cone_angle;      /* half-angle, radians, [0, pi]; 0 = along the axis; uniform over
                              the cone's solid angle */
    float speed_min;       /* m/s; speed uniform in [speed_min, speed_max] */
    float speed_max;       /* m/s; below speed_min -> speed_min */
    float lifetime_min;    /* seconds; lifetime uniform in [min, max] */
    float lifetime_max;    /* seconds; 0 (with min 0) -> INFINITY (never dies) */
    float size_min;        /* metres; 0 -> 0.05 */
    float size_max;        /* metres; below size_min -> size_min */
    float mass;            /* kg of each particle; 0 -> 1 (emitted particles are never pinned) */
    ak_vec4 colour;        /* all zero -> opaque white */
    ak_vec3 base_velocity; /* added to every emitted velocity (a moving emitter), m/s */
    float rate;            /* particles per second for ak_particles_emit; 0 = none */
    double carry;          /* fraction carried between calls; written by ak_particles_emit
                              (start at 0) */
    /* MESH: positions and triangle indices (world space, e.g. the skinned pose of this frame),
     * and scratch for the area table: mesh_area_cdf.count >= triangle count. */
    ak_vec3_cspan mesh_positions;
    ak_u32_cspan mesh_indices; /* 3 per triangle */
    ak_f32_span mesh_area_cdf;
} ak_particle_emitter;

/* Emit floor(carry + rate * dt) particles (with carry kept in double and a count within 1e-4
 * of an integer rounded up to it, which absorbs float time steps such as 0.01f: 2.5/s for
 * 200 steps of 0.01f emits exactly 5), updating
 * emitter->carry. Particles beyond capacity are dropped (the count still advances the carry).
 * *out_emitted (optional) gets the number added. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (dt
 * or rate negative or not finite, shape out of range, cone_angle outside [0, pi], negative
 * ranges), AK_ERR_EMPTY / AK_ERR_BAD_INDEX / AK_ERR_SPAN_SMALL (MESH: no triangles or zero
 * area, an index out of range, mesh_area_cdf too short). New particles have age 0 and are
 * stepped with the others on the next step. */
AK_API ak_result ak_particles_emit(ak_particles* particles, ak_particle_emitter* emitter, float dt,
                                   uint32_t* out_emitted);
/* Emit count particles at once (rate and carry are not used). Same codes as emit. */
AK_API ak_result ak_particles_burst(ak_particles* particles, const ak_particle_emitter* emitter,
                                    uint32_t count, uint32_t* out_emitted);

/* ---- forces ------------------------------------------------------------------------- */

/* F = strength * d / (|d|^2 + softening^2)^(3/2), d = position - particle: strength > 0
 * attracts, < 0 repels (Plummer softening, finite at the centre). */
typedef struct ak_particle_attractor {
    ak_vec3 position;
    float strength;  /* N m^2 */
    float softening; /* metres; 0 = none (a particle exactly at the centre then feels 0) */
} ak_particle_attractor;

/* Swirl about an axis: F = strength * (axis x r) / (|r|^2 + softening^2), r the particle's
 * offset from the axis line (perpendicular part); counter-clockwise about axis for > 0. */
typedef struct ak_particle_vortex {
    ak_vec3 center;
    ak_vec3 axis;    /* normalised here; zero -> +Y */
    float strength;  /* N m */
    float softening; /* metres; 0 = none */
} ak_particle_vortex;

/* Damped spring between particles i and j: along u = (p_j - p_i)/|p_j - p_i|,
 * F_i = (k (|p_j - p_i| - rest) + damping ((v_j - v_i) . u)) u, F_j = -F_i. Coincident
 * endpoints feel no force. */
typedef struct ak_particle_spring {
    uint32_t i, j; /* particle indices (see the note on indices above) */
    float rest;    /* metres */
    float k;       /* N/m */
    float damping; /* N s/m */
} ak_particle_spring;

/* Lennard-Jones between every pair closer than cutoff: V(r) = 4 epsilon ((sigma/r)^12 -
 * (sigma/r)^6), F_i = 24 epsilon (2 (sigma/r)^12 - (sigma/r)^6) (p_i - p_j) / r^2, the plain
 * truncated potential (not shifted: the force jumps from F(cutoff) to 0 at the cut-off). Pairs
 * are found with the neighbour grid (cells of size cutoff). Coincident particles feel nothing.
 * Work budget: the distance tests of one force evaluation (ak_grid_candidate_count of the
 * particles at the start of the step) must not exceed max_pair_tests, or the step returns
 * AK_ERR_BUDGET and changes nothing: particles packed into a few cells (or a cut-off spanning
 * the whole system) make the pass quadratic, 5e9 tests for 100,000 particles in one cell. */
#define AK_PARTICLES_LJ_DEFAULT_PAIR_TESTS 50000000u
typedef struct ak_particle_lennard_jones {
    float epsilon;           /* joules; 0 = off */
    float sigma;             /* metres */
    float cutoff;            /* metres; 0 -> 2.5 sigma */
    uint64_t max_pair_tests; /* 0 -> AK_PARTICLES_LJ_DEFAULT_PAIR_TESTS (5e7, about 0.1-0.5 s) */
} ak_particle_lennard_jones;

/* Caller forces: add newtons to force[0 .. count) for the given state (which may be an
 * intermediate RK4/Verlet stage). Called on the calling thread. */
typedef void (*ak_particle_force_fn)(const ak_vec3* position, const ak_vec3* velocity,
                                     const float* inv_mass, size_t count, double time,
                                     ak_vec3* force, void* user);

/* ---- colliders ---------------------------------------------------------------------- */

/* Response of every collider: the normal velocity at contact becomes -restitution times
 * itself; the tangential velocity loses at most friction times the normal velocity change
 * (Coulomb), stopping when that is more. Particles stay on the outside. */

/* The half-space n . x >= d is free space (n normalised here). */
typedef struct ak_particle_plane {
    ak_vec3 normal;    /* zero -> +Y */
    float d;           /* metres: offset along normal */
    float restitution; /* [0, 1] */
    float friction;    /* Coulomb coefficient, >= 0 */
} ak_particle_plane;

/* A solid sphere. */
typedef struct ak_particle_sphere {
    ak_vec3 center;
    float radius; /* metres, >= 0 */
    float restitution;
    float friction;
} ak_particle_sphere;

/* A solid axis-aligned box. */
typedef struct ak_particle_box {
    ak_vec3 min, max; /* min <= max per axis */
    float restitution;
    float friction;
} ak_particle_box;

/* A triangle mesh (two-sided; particles bounce off the side they come from), with a grid of
 * its triangle centroids so a particle tests only the triangles near its path. For a moving
 * mesh (a posed character) call ak_particle_mesh_update with the pose at the end of the
 * coming step: each vertex then has the velocity (new - old) / elapsed, a step of h tests the
 * particle's path against each triangle moving by its mean vertex velocity times h, and the
 * response (restitution, friction) uses the velocity relative to the surface, so a rising
 * surface carries particles up. Contacts leave particles 1e-5 m off the surface. */
typedef struct ak_particle_mesh ak_particle_mesh;

typedef struct ak_particle_mesh_desc {
    ak_vec3_cspan positions; /* world space */
    ak_u32_cspan indices;    /* 3 per triangle, required */
    float restitution;
    float friction;
} ak_particle_mesh_desc;

/* Copies the triangles and builds their grid. Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (no
 * triangles), AK_ERR_BAD_ARG (indices.count not a multiple of 3), AK_ERR_BAD_INDEX,
 * AK_ERR_BAD_DATA (non-finite positions), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_particle_mesh_create(const ak_particle_mesh_desc* desc,
                                         const ak_allocator* alloc, ak_particle_mesh** out_mesh);
/* New vertex positions for the same triangles (positions.count >= the count at create),
 * reached `elapsed` seconds after the previous ones; elapsed 0 = a jump (velocities 0).
 * Rebuilds the grid without allocating. AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_ARG
 * (elapsed negative or not finite), AK_ERR_BAD_DATA (a non-finite position). */
AK_API ak_result ak_particle_mesh_update(ak_particle_mesh* mesh, ak_vec3_cspan positions,
                                         float elapsed);
/* NULL is a no-op. */
AK_API void ak_particle_mesh_destroy(ak_particle_mesh* mesh);

typedef struct ak_particle_plane_cspan {
    const ak_particle_plane* ptr;
    size_t count;
} ak_particle_plane_cspan;
typedef struct ak_particle_sphere_cspan {
    const ak_particle_sphere* ptr;
    size_t count;
} ak_particle_sphere_cspan;
typedef struct ak_particle_box_cspan {
    const ak_particle_box* ptr;
    size_t count;
} ak_particle_box_cspan;
typedef struct ak_particle_spring_cspan {
    const ak_particle_spring* ptr;
    size_t count;
} ak_particle_spring_cspan;
typedef struct ak_particle_attractor_cspan {
    const ak_particle_attractor* ptr;
    size_t count;
} ak_particle_attractor_cspan;
typedef struct ak_particle_vortex_cspan {
    const ak_particle_vortex* ptr;
    size_t count;
} ak_particle_vortex_cspan;
typedef struct ak_particle_mesh_cspan {
    const ak_particle_mesh* const* ptr;
    size_t count;
} ak_particle_mesh_cspan;

/* Everything acting on the particles during a step. Zero = nothing (no gravity, still air). */
typedef struct ak_particles_world {
    ak_vec3 gravity;      /* m/s^2, an acceleration (acts on every unpinned particle) */
    float drag_linear;    /* N s/m: F = -drag_linear (v - wind) */
    float drag_quadratic; /* N s^2/m^2: F = -drag_quadratic |v - wind| (v - wind) */
    ak_vec3 wind;         /* m/s: velocity of the air the drag pulls towards */
    ak_particle_attractor_cspan attractors;
    ak_particle_vortex_cspan vortices;
    ak_particle_spring_cspan springs;
    ak_particle_lennard_jones lennard_jones;
    ak_particle_force_fn callback; /* NULL = none */
    void* callback_user;
    ak_particle_plane_cspan planes;
    ak_particle_sphere_cspan spheres;
    ak_particle_box_cspan boxes;
    ak_particle_mesh_cspan meshes;
} ak_particles_world;

/* Advance by dt: forces, integration, collisions, ageing (age += dt), removal of the dead.
 * Returns AK_ERR_NULL_ARG (particles, world, or a span with count > 0 and a NULL pointer),
 * AK_ERR_BAD_ARG (dt not > 0 and finite, restitution outside [0, 1], negative friction,
 * radius or drag, box min > max, LJ sigma <= 0 with epsilon != 0), AK_ERR_BAD_INDEX (a spring
 * index >= count), AK_ERR_BAD_DATA (non-finite world values), AK_ERR_BUDGET (Lennard-Jones
 * pairs over lennard_jones.max_pair_tests). On error nothing changes.
 * A particle whose state becomes non-finite (e.g. an exploding stiff spring) is removed at
 * the end of the step rather than poisoning the output. */
AK_API ak_result ak_particles_step(ak_particles* particles, const ak_particles_world* world,
                                   float dt);

/* ---- appearance over life (for rendering) --------------------------------------------- */

/* How a particle looks as it ages, as the fraction of its life t = age / lifetime in [0, 1]
 * (t = 0 for an infinite lifetime): its colour and size multiply keyframed curves, linear
 * between keys and held constant before the first and after the last, and its sprite-sheet
 * frame comes from its age. The system itself never reads this (rendering only). */
#define AK_PARTICLE_LOOK_MAX_KEYS 8

typedef struct ak_particle_colour_key {
    float t;        /* life fraction in [0, 1]; keys strictly increasing */
    ak_vec4 colour; /* multiplies the particle's colour (RGBA, alpha included) */
} ak_particle_colour_key;

typedef struct ak_particle_size_key {
    float t;    /* life fraction in [0, 1]; keys strictly increasing */
    float size; /* multiplies the particle's size, >= 0 */
} ak_particle_size_key;

typedef struct ak_particle_look {
    ak_particle_colour_key colour_keys[AK_PARTICLE_LOOK_MAX_KEYS];
    uint32_t colour_key_count; /* 0 -> the colour is not changed (a factor of 1, 1, 1, 1) */
    ak_particle_size_key size_keys[AK_PARTICLE_LOOK_MAX_KEYS];
    uint32_t size_key_count;   /* 0 -> the size is not changed (a factor of 1) */
    uint32_t frame_count;      /* frames of the sprite sheet; 0 -> 1 */
    float frame_rate;          /* frames per second from emission, looping; 0 -> the frames
                                  spread once over the lifetime (frame floor(t * frame_count)) */
} ak_particle_look;

/* AK_OK, or AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (a key count above AK_PARTICLE_LOOK_MAX_KEYS, a key
 * t outside [0, 1] or not increasing, a negative size, a non-finite value, frame_rate < 0). */
AK_API ak_result ak_particle_look_validate(const ak_particle_look* look);
/* Colour factor at the given age and lifetime (seconds; look NULL or without keys -> 1). */
AK_API ak_vec4 ak_particle_look_colour(const ak_particle_look* look, float age, float lifetime);
/* Size factor at the given age and lifetime (look NULL or without keys -> 1). */
AK_API float ak_particle_look_size(const ak_particle_look* look, float age, float lifetime);
/* Sprite-sheet frame in [0, frame_count) at the given age and lifetime (NULL -> 0). */
AK_API uint32_t ak_particle_look_frame(const ak_particle_look* look, float age, float lifetime);

/* ---- scene files and presets ------------------------------------------------------------ */
/* A particle scene: the JSON format of `animkit particles SCENE.json` (docs/particles.md lists
 * every key, its unit and its default) or a built-in preset, parsed into arrays the scene owns.
 * The same loader serves C, the Python package and the command:
 *     ak_particles_scene sc;
 *     ak_diag diag;
 *     if (ak_particles_scene_load_file("fountain.json", &sc, &diag) != AK_OK) {
 *         fprintf(stderr, "%s\n", diag.message);   // "fountain.json: emitters[0].rate: ..."
 *         return 1;
 *     }
 *     ... ak_particles_create(&(ak_particles_desc){.capacity = sc.capacity}, ...),
 *         ak_particles_add(...sc.particles...), ak_particles_step(ps, &sc.world, sc.dt) ...
 *     ak_particles_scene_free(&sc);
 * Emitters with bursts fire burst.count particles at burst.start, then every burst.interval
 * seconds (interval 0: once); the others emit at their rate. */

/* Bursts of one emitter of a scene: count particles at time start, then every interval. */
typedef struct ak_particles_scene_burst {
    uint32_t count;
    float start;    /* seconds */
    float interval; /* seconds; 0 = once */
} ak_particles_scene_burst;

/* How a scene's particles are drawn (its "render" key; docs/particles.md): round points (the
 * default) or camera-facing sprites with a texture, a sprite sheet, blending and colour/size
 * over life. The simulation never reads it; the command and the viewer draw with it. */
typedef struct ak_particles_scene_sprites {
    bool enabled;              /* false -> points */
    ak_sprite_texture texture; /* built-in texture when sheet_path is NULL: DISC or PUFF */
    char* sheet_path;          /* a PNG sprite sheet (owned by the scene; a relative "texture"
                                  is resolved against the scene file's directory), or NULL */
    int sheet_columns;         /* frames across; 0 -> 1 (built-in PUFF with frames: that many puffs) */
    int sheet_rows;            /* frames down; 0 -> 1 */
    ak_blend blend;            /* AK_BLEND_ALPHA (sorted back to front), AK_BLEND_ADD, or
                                  AK_BLEND_OPAQUE (alpha-tested cut-outs: leaves, grass) */
    ak_particle_look look;     /* colour, size and frame over life */
} ak_particles_scene_sprites;

/* A loaded scene: the world and everything to add, owning its arrays (ak_particles_scene_free).
 * world's spans point into the arrays below. */
typedef struct ak_particles_scene {
    float dt;                           /* seconds per step; default 0.01 */
    ak_particles_integrator integrator; /* default SYMPLECTIC */
    uint32_t capacity;                  /* default: particles + 100000 when there are emitters */
    ak_particles_world world;
    ak_particle_init* particles;        /* [particle_count] initial particles */
    size_t particle_count;
    ak_particle_spring* springs;        /* [world.springs.count] */
    ak_particle_plane* planes;
    ak_particle_sphere* spheres;
    ak_particle_box* boxes;
    ak_particle_attractor* attractors;
    ak_particle_vortex* vortices;
    ak_particle_emitter* emitters;      /* [emitter_count] */
    ak_particles_scene_burst* bursts;   /* [emitter_count]; count 0: the emitter uses its rate */
    size_t emitter_count;
    ak_particles_scene_sprites sprites; /* "render": how to draw the particles */
} ak_particles_scene;

/* Budgets a scene file may ask for, checked before allocating. */
#define AK_PARTICLES_SCENE_MAX_ITEMS 1000000u    /* particles, springs, colliders, emitters each */
#define AK_PARTICLES_SCENE_MAX_CAPACITY 2000000u /* about 0.5 GB of system state */
#define AK_PARTICLES_SCENE_MAX_FILE_SIZE ((size_t)64 << 20) /* bytes of a scene file */
/* The names ak_particles_scene_preset knows. */
#define AK_PARTICLES_SCENE_PRESETS "fountain, rain, fireworks, character, fire, smoke"

/* Parse a scene from bytes[0, size) (strict JSON, need not be NUL-terminated); name (NULL ->
 * "(scene)") starts every message. Emitter shape "mesh" is not allowed in files. A "render"
 * texture that is a relative .png path is resolved against name's directory (the file is not
 * read here: sprites.sheet_path holds the resolved path). Returns AK_OK
 * and fills *out_scene, or AK_ERR_PARSE (a syntax error, an unknown key, a value out of range or
 * over a budget), AK_ERR_NULL_ARG, with *out_scene empty and, when out_diag is not NULL, the one
 * line "NAME: key.path: problem" in out_diag->message (out_diag->path = name). */
AK_API ak_result ak_particles_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                               ak_particles_scene* out_scene, ak_diag* out_diag);
/* Read the file at path (at most AK_PARTICLES_SCENE_MAX_FILE_SIZE bytes) and parse it as
 * ak_particles_scene_load_bytes does, path naming it in messages. AK_ERR_IO when the file cannot
 * be opened or read or is too big ("PATH: cannot open the file"). */
AK_API ak_result ak_particles_scene_load_file(const char* path, ak_particles_scene* out_scene,
                                              ak_diag* out_diag);
/* The built-in scene name (AK_PARTICLES_SCENE_PRESETS; docs/particles.md gives their values).
 * "character" holds a mesh-surface emitter (sparks) and rain: the command supplies the
 * humanoid's posed mesh as collider and emitter surface; "fire" (additive) and "smoke"
 * (alpha-blended) draw built-in puff sprites. AK_ERR_NOT_FOUND for another name,
 * AK_ERR_NO_MEMORY. */
AK_API ak_result ak_particles_scene_preset(const char* name, ak_particles_scene* out_scene,
                                           ak_diag* out_diag);
/* Free the scene's arrays and zero it (safe on a zeroed, failed or freed scene; NULL: no-op). */
AK_API void ak_particles_scene_free(ak_particles_scene* scene);

/* ---- running a scene ------------------------------------------------------------------- */
/* Step a loaded scene exactly as `animkit particles` does, so that C and Python reproduce the
 * command's output: the scene's particles added in file order, each step every emitter emits
 * at its rate and fires the bursts due before the step's end (a bounded number of calls
 * whatever the interval), the system steps, and springs follow the file particles' new indices
 * as some die (springs to a dead particle go).
 *     ak_particles_scene_run run;
 *     if (ak_particles_scene_run_init(&run, &sc, &(ak_particles_scene_run_desc){.seed = 1}, &diag) == AK_OK)
 *         for (long k = 0; k < steps && ak_particles_scene_run_step(&run, &diag) == AK_OK; ++k) {}
 *     ak_particles_state st = ak_particles_get_state(run.system);   // the command's --json
 *     ak_particles_scene_run_free(&run); */
typedef struct ak_particles_scene_run_desc {
    uint64_t seed;                        /* the system's seed (the command uses 1) */
    uint32_t thread_count;                /* 0 -> 1 */
    const ak_particle_mesh* mesh_collider; /* optional: a mesh the caller poses between steps */
    ak_vec3_cspan mesh_positions;         /* optional: the surface of AK_EMITTER_MESH emitters */
    ak_u32_cspan mesh_indices;
    ak_f32_span mesh_area_cdf;            /* [mesh_indices.count / 3] */
} ak_particles_scene_run_desc;

typedef struct ak_particles_scene_run {
    ak_particles_scene* scene;   /* the scene run (its emitters' carry changes as they emit) */
    ak_particles* system;        /* the particle system: read its state between steps */
    ak_particles_world world;    /* the scene's world with the run's springs and collider mesh;
                                    a caller may change it between steps (wind, gravity...) */
    long step_index;             /* steps taken; step k ends at time (k + 1) * scene->dt */
    /* private */
    const ak_particle_mesh* meshes[1];
    uint64_t* fired;             /* bursts fired per emitter */
    ak_particle_spring* springs; /* the world's springs, re-indexed as file particles die */
    size_t file_alive;           /* file particles still alive */
} ak_particles_scene_run;

/* Create the system for scene (which must outlive the run) and add its particles. Returns
 * AK_OK, or the failing code with "particles: problem" in out_diag (optional); the run is then
 * safe to free. */
AK_API ak_result ak_particles_scene_run_init(ak_particles_scene_run* run, ak_particles_scene* scene,
                                             const ak_particles_scene_run_desc* desc, ak_diag* out_diag);
/* One step (number run->step_index): emit, fire due bursts, step, re-index springs. Returns
 * AK_OK or the failing code (AK_ERR_BUDGET: Lennard-Jones packed past its pair-test budget; the
 * message says what to lower) with "particles: step K: problem" in out_diag. */
AK_API ak_result ak_particles_scene_run_step(ak_particles_scene_run* run, ak_diag* out_diag);
/* Destroy the system and free the run's arrays (safe on a zeroed or failed run). */
AK_API void ak_particles_scene_run_free(ak_particles_scene_run* run);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_PARTICLES_H */
