/* animkit crowd: people walking on the ground plane without colliding (ORCA).
 *
 * What it does:
 *   - agents are discs on the ground plane (2D; an ak_vec2 {x, y} here is the world point
 *     (x, 0, y): y of the vec2 is world z), each with a radius, preferred and maximum speed,
 *     neighbour distance and count, time horizons, and a goal: a path of one or more waypoints;
 *   - static obstacles are polygons (vertices counter-clockwise; two vertices: a wall segment);
 *   - ORCA, "Optimal Reciprocal Collision Avoidance" (van den Berg, Guy, Lin, Manocha,
 *     "Reciprocal n-Body Collision Avoidance", ISRR 2011), as the paper and its reference
 *     library RVO2 compute it: one half-plane of velocities per neighbouring agent (each agent
 *     takes half the avoidance) and per nearby obstacle edge (the agent takes all of it), the
 *     new velocity is the one closest to the preferred velocity inside all half-planes and the
 *     max-speed disc (incremental 2D linear program, each line solved as a 1D program); when
 *     the half-planes leave no velocity, a 3D linear program minimises the largest violation
 *     of the agent half-planes while the obstacle half-planes stay hard;
 *   - neighbour selection as RVO2's: the max_neighbors nearest agents closer than
 *     neighbor_distance (ties by index; found on a cell-sorted dense grid, or the shared
 *     grid, grid.h, for sparse layouts, visiting rings of cells nearest first), every
 *     obstacle edge closer than time_horizon_obstacles * max_speed + radius, nearest first;
 *   - no overlap by default: ORCA alone lets agents overlap where its program is infeasible
 *     (dense crowds; RVO2 does too), so after the move the step repeats Gauss-Seidel contact
 *     passes until no pair and no obstacle edge overlaps by more than
 *     AK_CROWD_CONTACT_TOLERANCE, and reports the displacement as the velocity
 *     (allow_overlap: RVO2's pure ORCA);
 *   - the preferred velocity points at the current waypoint at pref_speed, and is the offset
 *     to the waypoint itself (per second) within pref_speed * 1 s of the last one, so agents
 *     slow down and stop on their goal (RVO2's examples do this for pref_speed 1); an agent
 *     moves on to its next waypoint once within waypoint_radius of the current one; unless
 *     skip_perturbation, it is turned to keep to one side (lanes form: see the job);
 *   - thread_count threads each take a range of agents; every agent reads only the step's
 *     inputs, so results are bit-identical for any thread count.
 *
 *   - AK_CROWD_VISION instead: synthetic-vision steering (Ondrej, Pettre, Olivier, Donikian,
 *     "A synthetic-vision based steering approach for crowd simulation", SIGGRAPH 2010): each
 *     agent casts vision_width rays over vision_fov around its heading against its neighbours'
 *     discs and the obstacle edges (a direct per-pixel ray cast: each pixel its object and hit
 *     point), or with vision_view RASTER renders them with raster.h into a vision_width x
 *     vision_height image (prisms and walls, object ids as flat colours, hit points from the
 *     depth); per pixel, the time to interaction tti (to the point's closest approach) and
 *     the bearing angle's rate; pixels whose |rate| is below the paper's threshold
 *     0.6 tti^-1.5 are threats; the agent turns toward its goal unless that leaves a threat
 *     under the threshold, then by the smallest heading change that lifts the rates of the
 *     threats on one side over it (keeping their signs; with threats on both sides, the side
 *     that keeps the passing side of the most imminent one; at most 3 rad/s; never so far
 *     that the goal leaves the view), and slows to pref_speed (1 - exp(-0.5 ttc_min^2)) over
 *     the threats' times to contact ttc; an agent standing (under 0.25 m/s, not coming
 *     closer) does not turn it and slows it to 30% at most. Within a second of its last goal
 *     (pref_speed * 1 s) it walks its preferred velocity, the offset to the goal per second,
 *     and stops there. No guarantee against overlap (the contact passes apply as for ORCA).
 *
 *   - characters: each agent drives a skinned character's in-place walk clip, its clip time
 *     following the distance walked (measured from the clip's stance foot: ak_crowd_gait_*),
 *     its heading the velocity, idle when stopped, its stance feet planted in the world (leg
 *     IK, ik.h's two-bone solver; a short step when pushed); the crowd baked into an animated scene
 *     for glTF (ak_crowd_bake_scene). See the "characters" sections below.
 *
 * What it does NOT do: dynamic obstacles, path planning (waypoints come from the caller), 3D
 * terrain (the ground is the plane y = 0).
 *
 * Usage:
 *     ak_vec2 goal[2] = {{10, 0}, {-10, 0}};
 *     ak_crowd_agent agents[2] = {{.goals = {&goal[0], 1}}, {.goals = {&goal[1], 1}}};
 *     ak_crowd_desc desc = {.agents = {agents, 2}};
 *     ak_crowd* crowd = NULL;
 *     if (ak_crowd_create(&desc, NULL, &crowd) != AK_OK) return 1;
 *     ak_vec2 p[2] = {{-10, 0}, {10, 0}}, v[2] = {{0}}, p2[2], v2[2];
 *     uint32_t wp[2] = {0, 0};
 *     ak_crowd_step_job job = {.crowd = crowd, .dt = 0.1f, .positions = {p, 2},
 *                              .velocities = {v, 2}, .waypoints = {wp, 2},
 *                              .out_positions = {p2, 2}, .out_velocities = {v2, 2}};
 *     size_t bytes = ak_crowd_step_scratch_size(&job);
 *     job.scratch = (ak_u8_span){malloc(bytes), bytes};
 *     for (int s = 0; s < 300; ++s) {
 *         ak_crowd_step_run(&job);        // then copy p2 -> p, v2 -> v (or swap the spans)
 *         memcpy(p, p2, sizeof p); memcpy(v, v2, sizeof v);
 *     }
 *     ak_crowd_destroy(crowd);
 *
 * Ownership and threading: ak_crowd_create copies everything it needs (agent parameters,
 * waypoints, obstacles) into one allocation; the built crowd is read-only and may be shared
 * by threads. The state (positions, velocities, waypoint indices) is caller-owned: the step
 * job reads the inputs, writes the outputs (which must not alias the inputs) and advances
 * each agent's waypoint index in place. The step never allocates: scratch comes from the
 * caller (a VISION crowd's RASTER view makes its render targets in it, about 0.5 MiB per
 * thread, instead of allocating them every step as before 2026-11-29);
 * thread_count > 1 starts pthreads.
 */
#ifndef ANIMKIT_CROWD_H
#define ANIMKIT_CROWD_H

#include "math.h"
#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AK_CROWD_MAX_AGENTS 10000000u   /* largest agent count a crowd accepts */
#define AK_CROWD_MAX_NEIGHBORS 64u      /* largest max_neighbors */
#define AK_CROWD_MAX_WAYPOINTS 1000000u /* waypoints over all agents */
#define AK_CROWD_MAX_OBSTACLE_VERTICES 100000u /* obstacle vertices over all obstacles */

/* One agent's parameters and goal path (cold configuration). */
typedef struct ak_crowd_agent {
    float radius;                 /* m; 0 -> 0.3 */
    float pref_speed;             /* m/s, speed toward the goal; 0 -> 1.3 */
    float max_speed;              /* m/s, >= pref_speed; 0 -> max(2, pref_speed) */
    float neighbor_distance;      /* m: agents closer than this are considered; 0 -> 5 */
    uint32_t max_neighbors;       /* the nearest this many count; 0 -> 10; <= 64 */
    float time_horizon;           /* s: ORCA avoids agents this far ahead; 0 -> 2 */
    float time_horizon_obstacles; /* s: and obstacles this far ahead; 0 -> 2 */
    float waypoint_radius;        /* m: an intermediate waypoint counts as passed this close;
                                     0 -> radius */
    ak_vec2_cspan goals;          /* required: waypoints (ground x, z), the last is the goal */
} ak_crowd_agent;

/* A static polygon: vertices counter-clockwise seen from above (+y looking down with x to
 * the right and z down, i.e. positive signed area in (x, z)); two vertices: a segment that
 * blocks from both sides. */
typedef struct ak_crowd_obstacle {
    ak_vec2_cspan vertices; /* >= 2, ground (x, z) m */
} ak_crowd_obstacle;

/* How a VISION agent's view is made (ak_crowd_desc.vision_view). */
typedef enum ak_crowd_view {
    AK_CROWD_VIEW_RAYCAST = 0, /* default: a 1D view, vision_width rays at equal angles over
                                  vision_fov, cast against the neighbours' discs and the
                                  obstacle edges (exact hit points, no rasterizer) */
    AK_CROWD_VIEW_RASTER,      /* the paper's way: raster.h renders each agent's surroundings
                                  into a vision_width x vision_height image (see below) */
    AK_CROWD_VIEW_COUNT
} ak_crowd_view;

/* The scene a RASTER view renders, per agent: a level perspective camera at its centre,
 * AK_CROWD_VISION_EYE_HEIGHT above the ground, looking along its heading, vision_fov wide
 * and AK_CROWD_VISION_VFOV degrees high (so every pixel of a column has the same bearing:
 * column k looks along the heading turned by atan(tan(vision_fov / 2) (1 - 2 (k + 0.5) /
 * vision_width)) from x toward z, column 0 the agent's right, the image's column
 * vision_width - 1 - k; planar projection, so the columns are narrower toward the edges); each
 * neighbour a vertical AK_CROWD_VISION_PRISM_SIDES-sided prism round its disc (faces
 * touching the circle), AK_CROWD_VISION_AGENT_HEIGHT tall, each obstacle edge a wall
 * AK_CROWD_VISION_WALL_HEIGHT tall, seen from both sides; no ground. Each object is drawn
 * UNLIT in a flat colour that is its id, and each pixel's hit point comes from the depth
 * buffer (ak_raster_read_samples); then the same per-pixel rule as the ray cast. */
#define AK_CROWD_VISION_EYE_HEIGHT 1.6f   /* m */
#define AK_CROWD_VISION_AGENT_HEIGHT 1.8f /* m */
#define AK_CROWD_VISION_WALL_HEIGHT 2.5f  /* m */
#define AK_CROWD_VISION_VFOV 80.0f        /* degrees (the paper's 80) */
#define AK_CROWD_VISION_PRISM_SIDES 8u

/* Avoidance method. */
typedef enum ak_crowd_method {
    AK_CROWD_ORCA = 0, /* default: velocity-based (ORCA) */
    AK_CROWD_VISION,   /* synthetic vision (Ondrej et al. 2010), see ak_crowd_desc */
    AK_CROWD_METHOD_COUNT
} ak_crowd_method;

typedef struct ak_crowd_desc {
    struct {
        const ak_crowd_agent* ptr;
        size_t count;
    } agents;                            /* required: 1 ..= AK_CROWD_MAX_AGENTS */
    const ak_crowd_obstacle* obstacles;  /* optional: [obstacle_count] */
    uint32_t obstacle_count;
    ak_crowd_method method;              /* 0 -> ORCA */
    uint32_t vision_width;               /* VISION: pixels across each agent's view (RAYCAST:
                                            the 1D view; RASTER: the image's width); 0 -> 48;
                                            <= 1024 */
    float vision_fov;                    /* VISION: field of view, degrees; 0 -> 150; < 360
                                            (RASTER: < 180) */
    ak_crowd_view vision_view;           /* VISION: 0 -> RAYCAST; RASTER renders with raster.h
                                            (one render target per thread, made in the step's
                                            scratch: neither view allocates) */
    uint32_t vision_height;              /* VISION RASTER: image rows; 0 -> 8; <= 256 */
} ak_crowd_desc;

typedef struct ak_crowd ak_crowd;

/* An agent with every zero default filled in (NULL -> all defaults; goals are kept). */
AK_API ak_crowd_agent ak_crowd_agent_resolved(const ak_crowd_agent* agent);

/* Build a crowd. alloc may be NULL (malloc/free). Returns AK_ERR_NULL_ARG (desc, out_crowd,
 * agents.ptr, an agent's goals.ptr, obstacles with obstacle_count > 0, an obstacle's
 * vertices), AK_ERR_EMPTY (no agents, an agent without waypoints), AK_ERR_BAD_ARG (a
 * parameter negative or not finite, max_speed < pref_speed, max_neighbors > 64, an obstacle
 * with fewer than 2 vertices, an unknown method or view, vision_width > 1024,
 * vision_height > 256, vision_fov not in [0, 360) ([0, 180) for RASTER) or not finite, counts above the AK_CROWD_MAX_* limits),
 * AK_ERR_BAD_DATA (a NaN or infinite waypoint or vertex, or beyond 1e7 m; an obstacle edge
 * of zero length), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_crowd_create(const ak_crowd_desc* desc, const ak_allocator* alloc, ak_crowd** out_crowd);

/* Free a crowd (NULL: no-op). */
AK_API void ak_crowd_destroy(ak_crowd* crowd);

/* Number of agents (0 for NULL). */
AK_API size_t ak_crowd_agent_count(const ak_crowd* crowd);

/* Agent i's resolved parameters (its goals span points into the crowd). i out of range or
 * NULL crowd -> a zero agent. */
AK_API ak_crowd_agent ak_crowd_agent_get(const ak_crowd* crowd, size_t index);

/* Whether agent i, at position p with current waypoint index wp, has reached its final goal:
 * wp is its last waypoint and |p - goal| <= radius (RVO2's examples' test). */
AK_API bool ak_crowd_goal_reached(const ak_crowd* crowd, size_t index, ak_vec2 position, uint32_t waypoint);

/* ---- the step job --------------------------------------------------------------------- */

typedef struct ak_crowd_step_job {
    const ak_crowd* crowd;       /* required */
    float dt;                    /* s, required: > 0 and finite */
    uint32_t thread_count;       /* 0 or 1 -> the calling thread; <= 64 */
    ak_vec2_cspan positions;     /* required: [agent_count] ground (x, z) m */
    ak_vec2_cspan velocities;    /* required: [agent_count] m/s */
    ak_u32_span waypoints;       /* required: [agent_count] current waypoint index (in/out:
                                    advanced in place; out-of-range values are clamped) */
    ak_vec2_cspan pref_velocities; /* optional: [agent_count] preferred velocities that
                                    replace the goal rule (the caller steers); empty -> goals */
    ak_u8_span scratch;          /* >= ak_crowd_step_scratch_size(job) bytes */
    ak_vec2_span out_positions;  /* [agent_count]: p + dt * v_new; must not alias inputs */
    ak_vec2_span out_velocities; /* [agent_count]: the ORCA velocity; must not alias inputs */
    uint64_t max_cell_load;      /* work budget: sum over the grid's cells of (agents in the
                                    cell)^2; 0 -> AK_CROWD_DEFAULT_CELL_LOAD */
    uint64_t step_index;         /* the step number: seeds the perturbation below */
    bool skip_perturbation;      /* false -> each preferred velocity is turned by -0.01 rad
                                    in (x, z) (every agent to the same side, as people keep
                                    to one side) and gets a deterministic jitter below
                                    1e-4 m/s (a hash of agent index and step_index): they
                                    break the symmetric deadlocks of ORCA (four agents
                                    crossing head-on, a ring of agents blocking each other at
                                    the circle's centre); and, for ORCA, the side
                                    preference: while an agent walks at 90% of its
                                    pref_speed or more, its preferred velocity turns a
                                    further 0.15 rad to that side, and up to 0.35 rad more
                                    (the more the nearer) when a neighbour ahead heads
                                    toward it and is not already clearly on that side, so
                                    that people walking in opposite directions pass on one
                                    side and form lanes (docs/crowd.md, "Jams"); true ->
                                    the preferred velocity as is (RVO2's bits:
                                    bench/vs_rvo2) */
    uint32_t contact_iterations; /* with allow_overlap: 0 -> pure ORCA, which lets agents
                                    overlap when the crowd is so dense that its program is
                                    infeasible (the 3D program then only minimises the
                                    violation; RVO2 does the same); n > 0 -> after the ORCA
                                    move, n Gauss-Seidel passes (on the calling thread,
                                    pairs in the grid's order) move each overlapping pair
                                    apart to touching and agents out of obstacle edges;
                                    velocities stay ORCA's. Without allow_overlap: the
                                    least number of passes. <= 64 */
    bool allow_overlap;          /* false (default) -> no overlap: after the move, the
                                    hard-contact projection repeats contact passes until
                                    none finds a pair or an obstacle edge overlapping by
                                    more than AK_CROWD_CONTACT_TOLERANCE (at most
                                    AK_CROWD_MAX_CONTACT_PASSES; from a step's 32nd pass
                                    on, pairs are over-relaxed: moved apart by 1.9 times
                                    their overlap, so that a press against a wall
                                    converges). true -> RVO2's behaviour:
                                    only the contact_iterations passes (0: pure ORCA, whose
                                    positions overlap where its program is infeasible;
                                    bench/vs_rvo2) */
    bool orca_velocities;        /* with allow_overlap false: false (default) ->
                                    out_velocities are the displacement over dt after the
                                    projection (what the agent did: an agent pushed back by
                                    its neighbours does not keep pressing on them); true ->
                                    ORCA's velocity */
} ak_crowd_step_job;

/* The hard-contact projection's tolerance (m) and its most passes in one step. */
#define AK_CROWD_CONTACT_TOLERANCE 1e-4f
#define AK_CROWD_MAX_CONTACT_PASSES 1024u

/* Agents stacked on a few points make the neighbour search quadratic; above this load the
 * step returns AK_ERR_BUDGET (about 4,000 agents in one cell). */
#define AK_CROWD_DEFAULT_CELL_LOAD 20000000u

/* Scratch bytes for this job (reads crowd, thread_count, contact_iterations, allow_overlap); 0 when the
 * job cannot be sized (validate says why). */
AK_API size_t ak_crowd_step_scratch_size(const ak_crowd_step_job* job);

/* First failing rule: AK_ERR_NULL_ARG (job, crowd, a required span), AK_ERR_BAD_ARG (dt not
 * > 0 and finite, thread_count > 64, contact_iterations > 64, outputs aliasing inputs), AK_ERR_SPAN_SMALL (a span
 * shorter than the agent count, scratch too small), AK_ERR_BAD_DATA (a NaN or infinite
 * position or velocity, or one beyond 1e7 m or m/s). */
AK_API ak_result ak_crowd_step_validate(const ak_crowd_step_job* job);

/* One ORCA step for every agent: neighbours, half-planes, linear program, then
 * p_out = p + dt * v_out (then the contact passes, when asked). Validates first and writes nothing on failure; besides the
 * validation codes returns AK_ERR_BUDGET (cell load above max_cell_load) and, for a VISION
 * crowd with the RASTER view, AK_ERR_NO_MEMORY (its render targets). */
AK_API ak_result ak_crowd_step_run(const ak_crowd_step_job* job);

/* ---- the linear program (exposed for tests and tools) --------------------------------- */

/* A half-plane of velocities: v is allowed when det(direction, point - v) <= 0, i.e. v lies
 * on the left of the directed line through point along direction (unit). */
typedef struct ak_crowd_line {
    ak_vec2 point;
    ak_vec2 direction;
} ak_crowd_line;

AK_DEFINE_SPAN(crowd_line, ak_crowd_line)

/* Agent i's ORCA half-planes for the given state: obstacle lines first (their count in
 * *out_obstacle_line_count), then agent lines, exactly as the step builds them. Writes
 * min(total, out_lines.count) lines and returns the total (0 on a bad argument). scratch as
 * for the step job (one thread). */
AK_API size_t ak_crowd_agent_lines(const ak_crowd_step_job* job, size_t index, ak_crowd_line_span out_lines,
                                   size_t* out_obstacle_line_count);

/* A VISION agent's view for the given state, per column (vision_width of them, column 0 the
 * agent's right: RAYCAST column k along the heading turned by vision_fov (0.5 - (k + 0.5) /
 * vision_width) from x toward z, RASTER as AK_CROWD_VISION_VFOV's comment says): the object the column
 * sees nearest (an agent's index; agent_count + v for the obstacle edge from obstacle vertex
 * v, vertices numbered over the obstacles in order; UINT32_MAX for nothing) and its hit
 * point's distance on the ground from the agent's centre (INFINITY for nothing); RASTER: the
 * nearest over the column's pixels. Among the objects the step looks at (the same neighbour
 * selection), with the heading the step uses (the velocity's direction, or the preferred
 * velocity's when standing). out_object / out_distance may be empty; else at least
 * vision_width long. Returns the column count, 0 on a bad argument (validation, index out
 * of range, not a VISION crowd, a span too small, no memory). scratch as for the step job. */
AK_API size_t ak_crowd_agent_view(const ak_crowd_step_job* job, size_t index, ak_u32_span out_object,
                                  ak_f32_span out_distance);

/* Solve ORCA's program: the velocity closest to pref within |v| <= max_speed satisfying every
 * line; when none exists, the velocity minimising the largest violation of lines
 * [obstacle_line_count, count) while lines [0, obstacle_line_count) stay satisfied.
 * scratch: >= lines.count ak_crowd_line entries (the 3D program's projected lines). Returns
 * the velocity; *out_feasible (optional) says whether the 2D program was feasible. */
AK_API ak_vec2 ak_crowd_solve(ak_crowd_line_cspan lines, size_t obstacle_line_count, float max_speed, ak_vec2 pref,
                              ak_crowd_line_span scratch, bool* out_feasible);

/* ---- measures ------------------------------------------------------------------------- */

/* Smallest |p_i - p_j| - r_i - r_j over all pairs (exact, in double: a grid pass over
 * pairs within reach of touching, else a sort-and-sweep on x) and the number of pairs closer
 * than r_i + r_j - overlap. positions.count <= agent count (the first agents); fewer than
 * two -> +infinity and 0. out_pairs (optional) receives the first out_pairs.count / 2
 * overlapping pairs as index pairs (i < j: i then j). scratch >=
 * ak_crowd_clearance_scratch_size(crowd, positions.count). Returns AK_ERR_NULL_ARG
 * (crowd, out_min_distance), AK_ERR_BAD_ARG (more positions than agents), AK_ERR_SPAN_SMALL,
 * AK_ERR_BAD_DATA (a non-finite position or beyond 1e7 m), AK_ERR_BUDGET (agents so stacked
 * that the grid's cell load, sum of (agents in a cell)^2 over cells of 2 x the largest
 * radius, exceeds AK_CROWD_DEFAULT_CELL_LOAD). */
AK_API size_t ak_crowd_clearance_scratch_size(const ak_crowd* crowd, size_t count);
AK_API ak_result ak_crowd_clearance(const ak_crowd* crowd, ak_vec2_cspan positions, float overlap,
                                    ak_u8_span scratch, float* out_min_distance, ak_u32_span out_pairs,
                                    size_t* out_overlap_count);

/* ---- scene files and presets ------------------------------------------------------------ */
/* A crowd scene: the JSON format of `animkit crowd SCENE.json` (docs/crowd.md lists every key,
 * its default and its range) or a preset, over the defaults:
 *     ak_crowd_scene sc;
 *     ak_diag diag;
 *     ak_crowd_scene_defaults(&sc);                        // or ak_crowd_scene_preset(...)
 *     if (ak_crowd_scene_load_file("corridor.json", &sc, &diag) != AK_OK) puts(diag.message);
 *     ak_crowd_desc desc = {.agents = {sc.agents, sc.agent_count}, .obstacles = sc.obstacles,
 *                           .obstacle_count = (uint32_t)sc.obstacle_count, .method = sc.method};
 *     ... ak_crowd_create(&desc, ...), then sc.steps steps of sc.dt from sc.positions and
 *         sc.velocities with sc.contact_iterations contact passes ...
 *     ak_crowd_scene_free(&sc); */

#define AK_CROWD_SCENE_MAX_AGENTS 1000000u    /* agents in a file or asked of a preset */
#define AK_CROWD_SCENE_MAX_OBSTACLES 10000u   /* obstacles in a file */
#define AK_CROWD_SCENE_MAX_VERTICES 100000u   /* obstacle vertices in a file, in all */
#define AK_CROWD_SCENE_MAX_PATH 1000u         /* waypoints of one agent's "path" */
#define AK_CROWD_SCENE_MAX_FILE_SIZE ((size_t)64 << 20)
/* The names ak_crowd_scene_preset knows. */
#define AK_CROWD_SCENE_PRESETS "circle, crossing, corridor, evacuation"
/* Agents of a preset asked for with count 0. */
#define AK_CROWD_SCENE_DEFAULT_AGENTS 100u

/* A loaded scene; it owns agents, positions, velocities, group, waypoints, obstacles and
 * vertices (malloc). */
typedef struct ak_crowd_scene {
    ak_crowd_agent defaults;      /* "agent_defaults": ak_crowd_agent_resolved(NULL) but
                                     waypoint_radius 0 (each agent's radius), no goals */
    ak_crowd_agent* agents;       /* [agent_count]: the defaults with the agent's own keys
                                     over them; goals point into waypoints */
    ak_vec2* positions;           /* [agent_count] start positions (ground x, z) */
    ak_vec2* velocities;          /* [agent_count] start velocities */
    uint8_t* group;               /* [agent_count] colour group when rendering */
    size_t agent_count;
    ak_vec2* waypoints;           /* every agent's path, one after another */
    size_t waypoint_count;
    ak_crowd_obstacle* obstacles; /* [obstacle_count]; vertices point into vertices */
    size_t obstacle_count;
    ak_vec2* vertices;
    size_t vertex_count;
    long steps;                   /* default 1000; a preset's: ceil(duration / dt) */
    float dt;                     /* s per step, default 0.1 */
    float duration;               /* s: a preset's run time, long enough for every agent to
                                     arrive (docs/crowd.md); 0 for the defaults and once a
                                     file sets "steps" */
    uint32_t contact_iterations;  /* default 8 */
    ak_crowd_method method;       /* default AK_CROWD_ORCA */
    ak_crowd_view vision_view;    /* "vision_view": "raycast" (default) or "raster" */
} ak_crowd_scene;

/* The defaults of every key (the scene without a file: no agents, no obstacles); owns
 * nothing. */
AK_API void ak_crowd_scene_defaults(ak_crowd_scene* scene);
/* Parse bytes[0, size) (strict JSON) OVER the scene already in *scene, which must hold
 * ak_crowd_scene_defaults or a preset (keys absent from the file keep its values; "agents"
 * and "obstacles", when present, replace the scene's; a preset's steps follow a "dt" of the
 * file unless it sets "steps"); name (NULL -> "(scene)") starts every message. The scene must
 * end with at least one agent. Returns AK_OK, or AK_ERR_PARSE / AK_ERR_NULL_ARG with, when
 * out_diag is not NULL, the one line "NAME: key.path: problem" in out_diag->message
 * ("t.json: agents[3].path[1]: expected [x, z], two numbers"). In every case *scene owns its
 * arrays afterwards: free it with ak_crowd_scene_free. */
AK_API ak_result ak_crowd_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                           ak_crowd_scene* scene, ak_diag* out_diag);
/* Read the file at path (at most AK_CROWD_SCENE_MAX_FILE_SIZE bytes) and parse it over *scene
 * as ak_crowd_scene_load_bytes does; AK_ERR_IO when it cannot be read. */
AK_API ak_result ak_crowd_scene_load_file(const char* path, ak_crowd_scene* scene, ak_diag* out_diag);
/* The defaults, then the preset name (AK_CROWD_SCENE_PRESETS; docs/crowd.md gives their
 * layouts) with count agents (0 -> AK_CROWD_SCENE_DEFAULT_AGENTS): "circle" (on a circle,
 * each to the antipode), "crossing" (four blocks cross from the four sides), "corridor" (two
 * groups, 5 abreast, meet in an 8 m corridor between two walls; each group's goals lie
 * beyond the other's start), "evacuation" (a room empties through one
 * door). Sets duration, and steps = ceil(duration / dt). *out_scene is overwritten without
 * being freed (pass a new or freed scene). AK_ERR_NOT_FOUND for another name, AK_ERR_BAD_ARG
 * for count above AK_CROWD_SCENE_MAX_AGENTS, AK_ERR_NO_MEMORY, AK_ERR_NULL_ARG; on failure
 * *out_scene holds the defaults. */
AK_API ak_result ak_crowd_scene_preset(const char* name, size_t count, ak_crowd_scene* out_scene,
                                       ak_diag* out_diag);
/* Free the arrays (NULL: no-op; safe twice); the scalar keys stay. */
AK_API void ak_crowd_scene_free(ak_crowd_scene* scene);


/* ---- characters: a walk cycle per agent ------------------------------------------------- */
/* Each agent drives a skinned character (builtin:humanoid's "walk", or any in-place walk
 * clip): the clip's time follows the distance the agent walks, its heading follows the
 * velocity (smoothed), and it blends to the rest pose when it stops (docs/crowd.md,
 * "Characters"):
 *     ak_crowd_gait gait;
 *     ak_crowd_gait_desc gd = {.scene = humanoid, .clip_index = ak_scene_find_clip(humanoid, "walk")};
 *     if (ak_crowd_gait_measure(&gd, NULL, &gait, &diag) != AK_OK) ...;
 *     ak_crowd_character ch[N];
 *     for (i) ch[i] = ak_crowd_character_init(&gait, heading_i, phase_i);
 *     each step: ak_crowd_characters_update(&(ak_crowd_characters_job){.gait = &gait, .dt = dt,
 *                    .velocities = {v, N}, .characters = {ch, N}});
 *     then per agent: ak_crowd_character_pose(&gait, &ch[i], local) -> local joint transforms,
 *     ak_crowd_character_root(&gait, &ch[i], p[i]) -> the model-to-world matrix. */

/* Samples of the gait's distance table over one cycle. */
#define AK_CROWD_GAIT_SAMPLES 256u

typedef struct ak_crowd_gait_desc {
    const ak_scene* scene; /* required: a skeleton and the walk clip; kept by the gait */
    int clip_index;        /* the walk clip: a loop (its last pose equals its first) that
                              walks in place (no horizontal root motion: remove it first with
                              ak_clip_extract_root_motion) */
    int left_foot;         /* foot joints; both 0 -> automatic: the lowest joint of the rest
                              pose with x > 0 (left) and with x < 0 (right) */
    int right_foot;
} ak_crowd_gait_desc;

/* A walk clip measured once (a value: copy it freely). The stance foot at clip time t is the
 * lower of the two feet; over one cycle it travels stride_length backward (along -forward);
 * distance[k] is that travel accumulated from clip time 0 to k * duration /
 * AK_CROWD_GAIT_SAMPLES (non-decreasing, distance[0] = 0, distance[SAMPLES] =
 * stride_length). An agent that walked d metres shows the clip at the time where the
 * accumulated travel is d mod stride_length: its stance foot then moves back exactly as fast
 * as the agent moves forward, and the mean playback rate is speed / stride_speed. */
typedef struct ak_crowd_gait {
    const ak_scene* scene;
    int clip_index;
    int feet[2];          /* left, right joint */
    float duration;       /* s, the clip's */
    float stride_length;  /* m per cycle */
    float stride_speed;   /* m/s at playback rate 1: stride_length / duration */
    ak_vec3 forward;      /* model-space walking direction (unit, y = 0) */
    float foot_min_y[2];  /* model-space lowest height of each foot over the cycle */
    float distance[AK_CROWD_GAIT_SAMPLES + 1];
} ak_crowd_gait;

/* Measure the walk clip: sample it AK_CROWD_GAIT_SAMPLES times over its duration (forward
 * kinematics, model space), take the lower foot of each interval, forward = the opposite of
 * its mean horizontal motion, distance = its accumulated backward motion. alloc (NULL ->
 * malloc) holds two poses during the call. Returns AK_ERR_NULL_ARG (desc, scene, its
 * skeleton, out_gait), AK_ERR_BAD_INDEX (clip or foot joint out of range, both feet one
 * joint), AK_ERR_NOT_FOUND (no joint on one side for the automatic feet), AK_ERR_BAD_DATA
 * (a clip shorter than 1 ms, or one whose stance foot does not travel at least 1 cm per
 * cycle: not a walk), AK_ERR_NO_MEMORY; diag (optional) says why. */
AK_API ak_result ak_crowd_gait_measure(const ak_crowd_gait_desc* desc, const ak_allocator* alloc,
                                       ak_crowd_gait* out_gait, ak_diag* out_diag);

/* The clip time (in [0, duration)) at which the stance foot has travelled distance mod
 * stride_length (a negative or non-finite distance -> 0). */
AK_API float ak_crowd_gait_clip_time(const ak_crowd_gait* gait, float distance);

/* One agent's character state (caller-owned, one per agent). */
/* A foot's planting state (ak_crowd_character.foot_state). */
typedef enum ak_crowd_foot_state {
    AK_CROWD_FOOT_FREE = 0,  /* the clip's foot */
    AK_CROWD_FOOT_PINNED,    /* held at foot_pin by leg IK while the clip has it down */
    AK_CROWD_FOOT_RELEASING, /* lifted off by the clip: the pin fades out (foot_weight 1 -> 0) */
    AK_CROWD_FOOT_STEPPING   /* the pin got too far from the clip's foot while down: a short
                                step (the foot lifted on an arc) from foot_pin to the clip's */
} ak_crowd_foot_state;

/* Foot planting (ak_crowd_characters_job.positions; docs/crowd.md, "Foot planting"): a foot
 * the clip puts down (model height within AK_CROWD_PLANT_BAND of its lowest) is pinned where
 * it landed in the world and the leg is solved to it with ik.h's two-bone solver (the pelvis
 * lowered when a leg cannot reach, at most AK_CROWD_PLANT_MAX_DROP); at lift-off the pin
 * fades out over AK_CROWD_PLANT_RELEASE_TIME; a pin farther than AK_CROWD_PLANT_MAX_OFFSET
 * from the clip's foot (or needing more drop) makes the foot step: lifted by up to
 * AK_CROWD_PLANT_STEP_HEIGHT over AK_CROWD_PLANT_STEP_TIME onto the clip's foot (one foot at a
 * time). */
#define AK_CROWD_PLANT_BAND 0.02f         /* m above the foot's lowest model height */
#define AK_CROWD_PLANT_RELEASE_TIME 0.1f  /* s */
#define AK_CROWD_PLANT_MAX_OFFSET 0.15f   /* m, horizontal */
#define AK_CROWD_PLANT_MAX_DROP 0.06f     /* m */
#define AK_CROWD_PLANT_STEP_TIME 0.25f    /* s */
#define AK_CROWD_PLANT_STEP_HEIGHT 0.06f  /* m */

typedef struct ak_crowd_character {
    float distance;    /* m walked along the cycle, in [0, stride_length) */
    float clip_time;   /* s: ak_crowd_gait_clip_time(distance) */
    ak_vec2 heading;   /* unit facing on the ground (x, z) */
    float walk_weight; /* 1 walking .. 0 idle (the rest pose) */
    /* foot planting, per foot (left, right); all zero (free) unless the update gets positions */
    ak_vec2 foot_pin[2];      /* world (x, z) the foot is held at (PINNED, RELEASING) or steps
                                 from (STEPPING) */
    float foot_weight[2];     /* PINNED 1; RELEASING and STEPPING: 1 -> 0 as it ends */
    uint8_t foot_state[2];    /* ak_crowd_foot_state */
} ak_crowd_character;

AK_DEFINE_SPAN(crowd_character, ak_crowd_character)

/* A character facing heading (normalised; zero or non-finite -> +z), at the cycle phase
 * phase in [0, 1) (a fraction of the stride: give agents different phases so that they do
 * not all step together), walk_weight 0. */
AK_API ak_crowd_character ak_crowd_character_init(const ak_crowd_gait* gait, ak_vec2 heading, float phase);

typedef struct ak_crowd_characters_job {
    const ak_crowd_gait* gait;            /* required */
    float dt;                             /* s, > 0 and finite */
    ak_vec2_cspan velocities;             /* required: [count] the agents' velocities this step */
    ak_crowd_character_span characters;   /* in/out: [count] */
    float turn_time;     /* s: heading follows the velocity's direction with this time
                            constant (exponential smoothing); 0 -> 0.1 */
    float max_turn_rate; /* rad/s; 0 -> 6 */
    float idle_speed;    /* m/s: below it the character blends to the rest pose
                            (walk_weight = smoothstep(speed / idle_speed)) and keeps its
                            heading; 0 -> 0.15 */
    ak_vec2_cspan positions; /* optional: [count] the agents' ground positions after this
                                step -> foot planting (the foot_* fields; pose the
                                characters with ak_crowd_character_pose_planted); empty ->
                                no planting (the foot_* fields are left as they are) */
    ak_u8_span scratch;      /* with positions: >= ak_crowd_characters_scratch_size(gait) */
} ak_crowd_characters_job;

/* Scratch bytes ak_crowd_characters_update needs with positions (a pose of the gait's
 * skeleton); 0 for a NULL gait. */
AK_API size_t ak_crowd_characters_scratch_size(const ak_crowd_gait* gait);

/* Advance every character by dt: distance += |v| dt (wrapped), clip_time from the gait,
 * heading turned toward v (while |v| > idle_speed / 2), walk_weight from the speed; with
 * positions, then each foot's planting state (see AK_CROWD_PLANT_BAND) from the clip's foot
 * placed at the new position. Returns AK_ERR_NULL_ARG (job, gait, a span), AK_ERR_BAD_ARG
 * (dt not > 0 and finite, a negative or non-finite parameter), AK_ERR_SPAN_SMALL
 * (velocities or positions shorter than characters, scratch too small), AK_ERR_BAD_DATA (a
 * non-finite velocity or position: nothing is written). */
AK_API ak_result ak_crowd_characters_update(const ak_crowd_characters_job* job);

/* The character's local pose: the rest pose, the walk clip at clip_time over it, then every
 * joint blended toward the rest pose by 1 - walk_weight (translation and scale linearly,
 * rotation by SLERP). out_local.count >= the skeleton's joint count. Returns AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_crowd_character_pose(const ak_crowd_gait* gait, const ak_crowd_character* character,
                                         ak_transform_span out_local);

/* Model-to-world matrix of the character standing at ground position p: a rotation about +y
 * turning the gait's forward onto the heading, then the translation (p.x, 0, p.y). */
AK_API ak_mat4 ak_crowd_character_root(const ak_crowd_gait* gait, const ak_crowd_character* character, ak_vec2 p);

/* Shared poses for large crowds (docs/crowd.md, "Shared poses"): a renderer poses and skins
 * one character per bucket instead of one per agent. The character's clip time is rounded to
 * the nearest multiple of duration / phase_buckets (modulo the cycle) and its walk_weight to the
 * nearest of weight_levels evenly spaced levels in [0, 1] (0 and 1 included). With
 * AK_CROWD_PHASE_BUCKETS the clip time is off by at most duration / 256 (builtin:humanoid's
 * walk: 3.9 ms), so a skinned vertex is off by at most that times its largest speed in the clip
 * (builtin:humanoid: 2.28 m/s, 0.9 cm); 128 keeps the stance foot's slide walking straight under
 * 2 cm (measured 1.85-1.94 cm; 32 buckets: 4.8-5.1 cm). */
#define AK_CROWD_PHASE_BUCKETS 128u
#define AK_CROWD_WEIGHT_LEVELS 4u

/* The character's bucket (see AK_CROWD_PHASE_BUCKETS): 0 when walk_weight rounds to 0 (the rest
 * pose, whatever the phase), else 1 + (level - 1) * phase_buckets + phase index, below
 * ak_crowd_character_bucket_count(phase_buckets, weight_levels). When out is not NULL it gets
 * the character with clip_time and walk_weight snapped to the bucket's (heading, distance and
 * feet copied as they are): ak_crowd_character_pose of *out is the bucket's shared pose, the
 * same for every character of the bucket. Returns SIZE_MAX (out untouched) for a NULL gait or
 * character, a gait with no positive duration, phase_buckets 0 or weight_levels < 2. */
AK_API size_t ak_crowd_character_bucket(const ak_crowd_gait* gait, const ak_crowd_character* character,
                                        uint32_t phase_buckets, uint32_t weight_levels, ak_crowd_character* out);
/* The number of buckets: 1 + (weight_levels - 1) * phase_buckets (0 for phase_buckets 0 or
 * weight_levels < 2). */
AK_API size_t ak_crowd_character_bucket_count(uint32_t phase_buckets, uint32_t weight_levels);

/* ak_crowd_character_pose, then the feet planted (the character standing at ground position
 * p): each foot not FREE is pulled onto its target by the two-bone solver on its leg (the
 * foot's parent and grandparent: knee and hip; knee toward the gait's forward), weighted by
 * foot_weight: PINNED and RELEASING target foot_pin at the clip foot's height; STEPPING moves
 * from foot_pin to the clip's foot (smoothstep of the progress 1 - foot_weight) lifted by
 * AK_CROWD_PLANT_STEP_HEIGHT sin(pi progress). The pelvis (the skeleton's root joint) is
 * lowered, at most AK_CROWD_PLANT_MAX_DROP, where a leg cannot reach. Returns as
 * ak_crowd_character_pose. */
AK_API ak_result ak_crowd_character_pose_planted(const ak_crowd_gait* gait, const ak_crowd_character* character,
                                                 ak_vec2 p, ak_transform_span out_local);

/* ---- the crowd as an animated glTF scene ---------------------------------------------------- */

/* Recorded frames of a crowd with characters, to bake into a scene (frame-major arrays). */
typedef struct ak_crowd_bake_desc {
    const ak_crowd_gait* gait;                /* required: the character (gait->scene) */
    size_t agent_count;                       /* required, > 0 */
    size_t frame_count;                       /* required, 1 .. AK_SCENE_BAKE_MAX_FRAMES */
    const ak_vec2* positions;                 /* required: [frame_count * agent_count] */
    const ak_crowd_character* characters;     /* required: same layout */
    float frame_time;                         /* required: > 0 s between frames */
    const ak_vec4* colors;                    /* optional: [agent_count] base colours (linear
                                                 RGBA); NULL -> the character's materials */
    const char* name;                         /* scene, clip and node prefix; NULL -> "crowd" */
    size_t memory_budget;                     /* bytes; 0 -> AK_SCENE_BAKE_DEFAULT_BUDGET */
} ak_crowd_bake_desc;

/* Build an animated scene of the crowd (io.h's ak_io_save writes it as glTF): per agent a root
 * node "<name>_<i>" (translation and rotation keyed at every frame: the root matrix of
 * ak_crowd_character_root) holding a copy of the character's nodes ("<i>/<joint name>") with
 * their own skin, and one clip "<name>" keying, for every agent, the joint properties the walk
 * clip animates at every frame (ak_crowd_character_pose; LINEAR, rotations sign-continuous).
 * The character's meshes are copied once (agent 0's scene meshes own them) and every other
 * agent's scene meshes are instances of them (shares_mesh, scene.h) with the agent's skin and
 * colour, so ak_io_save writes the mesh data once. Agents: at most
 * AK_SKELETON_MAX_JOINTS / (the character's joint count + 1) (55,188 for builtin:humanoid).
 * Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (no agent or frame), AK_ERR_BAD_ARG (frame_time not
 * > 0 and finite), AK_ERR_BAD_DATA (a non-finite position), AK_ERR_UNSUPPORTED (more than
 * AK_SCENE_BAKE_MAX_FRAMES frames, more than AK_SKELETON_MAX_JOINTS nodes in all, or more bytes
 * than memory_budget (ak_crowd_bake_max_frames): checked before allocating; diag gives the
 * numbers), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_crowd_bake_scene(const ak_crowd_bake_desc* desc, const ak_allocator* alloc, ak_scene** out_scene,
                                     ak_diag* out_diag);

/* The most frames ak_crowd_bake_scene takes for agent_count agents of gait's character within
 * memory_budget (0 -> AK_SCENE_BAKE_DEFAULT_BUDGET) and AK_SCENE_BAKE_MAX_FRAMES, by the estimate
 * it checks before allocating; 0 when not even one frame fits (or gait is NULL, or the agents'
 * nodes pass AK_SKELETON_MAX_JOINTS). */
AK_API size_t ak_crowd_bake_max_frames(const ak_crowd_gait* gait, size_t agent_count, size_t memory_budget);

#ifdef __cplusplus
}
#endif

#endif
