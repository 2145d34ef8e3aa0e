/* animkit rigid: rigid bodies (spheres, boxes, capsules, convex hulls; static planes,
 * heightfields and triangle meshes), contacts, joints,
 * ragdolls.
 *
 * What it does:
 *   - a model (ak_rigid_model) holds each body's shape, mass, inertia and material; it is built
 *     once from descs and is read-only afterwards;
 *   - mass and inertia tensor from the shape and a density (kg/m^3) or a given mass; static
 *     bodies (and every plane) have infinite mass;
 *   - dynamics: position, quaternion orientation, linear and angular velocity in world space; the
 *     gyroscopic term -w x (I w) is integrated implicitly in the body frame (one Newton step of
 *     backward Euler per substep, as in Box2D v3 / Catto GDC 2015), so a torque-free box spinning
 *     near its intermediate axis flips and angular momentum stays (see docs/rigid.md);
 *     linear and angular damping;
 *   - solver: XPBD rigid bodies with substeps (Mueller, Macklin, Chentanez, Jeschke, Kim 2020,
 *     "Detailed Rigid Body Simulation with Extended Position Based Dynamics"): the pairs are
 *     found once per step with margins that cover the step's motion; each substep predicts,
 *     takes the contacts (box and plane pairs keep the points found at the step's start, the
 *     others run the narrow phase on the predicted state), projects non-penetration and static
 *     friction on positions, derives velocities, then applies dynamic friction and restitution;
 *   - contacts: sweep-and-prune broad phase along the axis of the bodies' largest spread,
 *     closed-form narrow phase for every pair of sphere, box, capsule and plane (box-box:
 *     separating axis test over the 15 axes, then the incident face clipped against the
 *     reference face for a manifold of up to 8 points); hulls against every convex shape by GJK
 *     (distance) and, when the shapes' cores overlap, a separating axis test over faces and
 *     Gauss-map-pruned edge pairs, then the same face clipping; contacts are found within
 *     contact_offset of touching (speculative); a contact's friction is the geometric mean of
 *     its bodies' and its restitution the larger of the two; pairs are solved from the top down;
 *   - joints: ball (optional swing cone and twist range), hinge (optional angle limits), fixed,
 *     prismatic (optional distance limits), with compliance, and drives towards a target
 *     relative orientation (XPBD positional and angular constraints, their section 3.3);
 *   - ragdolls: a capsule per bone of a skeleton (sized from the bone, or fitted to the
 *     vertices of a skin) and a joint per joint with the skeleton's limits, started from an
 *     animated pose (and its velocities), written back as a pose; powered, its joints driven
 *     towards an animation's pose each step (drive_targets);
 *   - sleeping: a connected group of touching or joined bodies whose speeds all stay under the
 *     thresholds for sleep_time seconds is frozen until an awake body touches it;
 *   - deterministic: the same inputs give the same bits (contacts are found and solved in an
 *     order fixed by the positions and body indices), whatever the thread count: each step the
 *     bodies joined by contact pairs or joints form islands (a ragdoll on the ground is one, a
 *     pyramid is one), solved whole, substeps and all, one after another; thread_count shares
 *     the islands out among the library's worker team. When the contact buffer cannot give
 *     every island a region of its own (max_contacts), the step solves the world as one island
 *     and thread_count shares out only its joint sweeps, chain by chain (joints that share
 *     moving bodies). Either way the numbers are the same to the bit.
 *
 * What it does NOT do (yet): threads within one island (a single pile gains nothing), continuous
 * collision detection (a body moving more than its size in one substep can tunnel), dynamic
 * triangle meshes and heightfields (they are static), two-way coupling with other simulations:
 * cloth and particles take the bodies as a mesh (ak_rigid_world_mesh), the fluid as its colliders
 * (ak_rigid_fluid_colliders), one-way.
 *
 * Usage (a box dropped on the ground):
 *     ak_rigid_body_desc bodies[2] = {
 *         { .shape = { .type = AK_RIGID_PLANE }, .is_static = true },
 *         { .shape = { .type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f} },
 *           .position = {0, 3, 0} } };
 *     ak_rigid_model* model = NULL;
 *     ak_rigid_model_desc md = { .bodies = { bodies, 2 } };
 *     if (ak_rigid_model_create(&md, NULL, &model) != AK_OK) return 1;
 *     ak_vec3 x[2], v[2], w[2]; ak_quat q[2];
 *     ak_rigid_initial_state(model, (ak_vec3_span){x, 2}, (ak_quat_span){q, 2},
 *                            (ak_vec3_span){v, 2}, (ak_vec3_span){w, 2});
 *     ak_rigid_step_job job = { .model = model, .dt = 1.0f / 60, .gravity = {0, -9.81f, 0},
 *         .positions = {x, 2}, .orientations = {q, 2}, .velocities = {v, 2},
 *         .angular_velocities = {w, 2} };
 *     size_t size = ak_rigid_step_scratch_size(&job);
 *     job.scratch = (ak_u8_span){ malloc(size), size };
 *     for (int f = 0; f < 120; ++f) if (ak_rigid_step_run(&job) != AK_OK) break;
 *     ak_rigid_model_destroy(model);
 *
 * Ownership and threading: ak_rigid_model_create makes one allocation; the model is read-only
 * afterwards and may be shared by threads. The state arrays and the scratch belong to the
 * caller; ak_rigid_step_run never allocates. Steps of distinct states may run concurrently.
 */
#ifndef ANIMKIT_RIGID_H
#define ANIMKIT_RIGID_H

#include "fluid.h" /* ak_fluid_collider (ak_rigid_fluid_colliders fills them; no link dependency) */
#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ak_rigid_shape_type {
    AK_RIGID_SPHERE = 0, /* default: radius */
    AK_RIGID_BOX,        /* half_extents along the body's local axes */
    AK_RIGID_CAPSULE,    /* segment along the local Y axis from -half_height to +half_height,
                            swept by radius */
    AK_RIGID_PLANE,      /* static half-space below the plane through position with normal
                            `normal` (world); the body's orientation is ignored */
    AK_RIGID_HULL,       /* convex hull of `points` (solid, uniform density); see below for
                            its frame */
    AK_RIGID_HEIGHTFIELD, /* static: a grid of heights (rows x cols samples `spacing` apart) */
    AK_RIGID_TRIMESH,     /* static: a triangle mesh (vertices, 3 indices per triangle) */
    AK_RIGID_COMPOUND,    /* several spheres, boxes, capsules and hulls fixed together */
    AK_RIGID_SHAPE_COUNT
} ak_rigid_shape_type;

typedef struct ak_rigid_shape {
    ak_rigid_shape_type type; /* 0 -> sphere */
    float radius;             /* metres; sphere and capsule: > 0 (required) */
    ak_vec3 half_extents;     /* metres; box: each > 0 (required) */
    float half_height;        /* metres; capsule: half the segment's length, >= 0 */
    ak_vec3 normal;           /* plane: world normal (normalised here); zero -> (0, 1, 0) */
    ak_vec3_cspan points;     /* hull: 4 to AK_RIGID_HULL_MAX_POINTS points, in the shape's own
                                 frame, not all in one plane (interior points are allowed and
                                 dropped); read by ak_rigid_model_create only */
    /* heightfield (always static): sample (col, row), col < cols along the body's +X and row <
       rows along its +Z, is at (col * spacing, heights[row * cols + col], row * spacing) in the
       body frame (the body's position is sample (0, 0)'s foot); each cell is two triangles.
       animkit terrain's layout (include/animkit/terrain.h) is this one with cols = width, rows =
       height, spacing = world_size / (width - 1) and the position at its first sample's (x, 0,
       z). Copied by ak_rigid_model_create. */
    ak_f32_cspan heights;     /* rows * cols finite heights (m) */
    uint32_t rows, cols;      /* >= 2 each; rows * cols <= AK_RIGID_HEIGHTFIELD_MAX_SAMPLES */
    float spacing;            /* metres between neighbouring samples, > 0 */
    /* trimesh (always static): triangles (indices[3k], [3k+1], [3k+2]) of vertices in the body
       frame, counter-clockwise seen from the side bodies rest on (one-sided: a contact whose
       normal points into that side is dropped). Copied by ak_rigid_model_create, which builds a
       bounding volume hierarchy over the triangles. */
    ak_vec3_cspan vertices;
    ak_u32_cspan indices;     /* 3 per triangle, each < vertices.count; at most
                                 3 * AK_RIGID_TRIMESH_MAX_TRIANGLES */
    /* compound: 1 to AK_RIGID_COMPOUND_MAX_CHILDREN children (sphere, box, capsule or hull),
       placed in the shape frame, one density for all. Mass, centre of mass and inertia are the
       children's summed by the parallel axis theorem; the body frame is the centre of mass and
       the principal axes, resolved from the desc's pose as for a hull (see AK_RIGID_HULL).
       Children may overlap (their volumes then count twice). Read by ak_rigid_model_create
       only: the resolved desc (ak_rigid_body_get_desc) has no children (NULL, 0). */
    const struct ak_rigid_child* children;
    size_t child_count;
} ak_rigid_shape;

/* One shape of a compound body. */
typedef struct ak_rigid_child {
    ak_rigid_shape shape;     /* sphere, box, capsule or hull */
    ak_vec3 position;         /* the child's frame in the compound's shape frame (a hull's
                                 points are in the child's frame) */
    ak_quat orientation;      /* zero -> identity */
} ak_rigid_child;

#define AK_RIGID_COMPOUND_MAX_CHILDREN 64u

/* Budgets of the static mesh shapes (checked before anything is allocated). */
#define AK_RIGID_HEIGHTFIELD_MAX_SAMPLES (1u << 24)
#define AK_RIGID_TRIMESH_MAX_TRIANGLES (1u << 22)

/* Most points a hull may be built from (the build is O(n^2) in the worst case). */
#define AK_RIGID_HULL_MAX_POINTS 1024u

/* The hull's frame. A body's frame is always its centre of mass and principal axes, so that the
 * solver's inertia stays diagonal. For a hull the desc's position and orientation place the frame
 * the points were given in (the "shape frame"); ak_rigid_model_create computes the hull's centre
 * of mass c and principal axes R (in the shape frame) and resolves the desc to the body frame:
 * position + orientation * c and orientation * R. The resolved desc (ak_rigid_body_get_desc) and
 * the state hold that body frame; ak_rigid_body_shape_frame gives the shape frame back. When the
 * inertia about c is already diagonal (a box's corners, any hull symmetric about its axes) R is
 * the identity. The resolved shape's points are the hull's vertices in the body frame (owned by
 * the model). */

/* Friction value that means "none" (zero friction means the default). */
#define AK_RIGID_FRICTIONLESS (-1.0f)

typedef struct ak_rigid_body_desc {
    ak_rigid_shape shape;
    ak_vec3 position;         /* world, centre of mass (plane: a point on it) */
    ak_quat orientation;      /* body to world; zero -> identity (normalised here) */
    ak_vec3 velocity;         /* m/s, world */
    ak_vec3 angular_velocity; /* rad/s, world */
    float density;            /* kg/m^3 when mass is 0; 0 -> 1000 */
    float mass;               /* kg; 0 -> from density and the shape's volume */
    float friction;         /* Coulomb coefficient (static); 0 -> 0.5; AK_RIGID_FRICTIONLESS -> 0 */
    float dynamic_friction; /* Coulomb coefficient when sliding; 0 -> friction;
                               AK_RIGID_FRICTIONLESS -> 0 */
    float restitution;      /* normal velocity kept in a bounce, [0, 1]; 0 -> none */
    bool is_static;         /* infinite mass, never moves (planes always are) */
    uint32_t collision_group; /* bodies sharing a nonzero group do not collide with each other
                                 (a ragdoll's limbs); 0 -> collides with every body */
} ak_rigid_body_desc;

AK_DEFINE_SPAN(rigid_body_desc, ak_rigid_body_desc)

typedef enum ak_rigid_joint_type {
    AK_RIGID_JOINT_BALL = 0,  /* default: the anchors coincide; optional swing cone */
    AK_RIGID_JOINT_HINGE,     /* ball plus the bodies' axes stay parallel; optional angle limits */
    AK_RIGID_JOINT_FIXED,     /* ball plus the relative orientation stays as built */
    AK_RIGID_JOINT_PRISMATIC, /* relative orientation as built; b slides along the axis only;
                                 optional distance limits */
    AK_RIGID_JOINT_TYPE_COUNT
} ak_rigid_joint_type;

/* A joint between two bodies, described in world space at the bodies' desc poses (the model
 * stores each body's local anchor and axes from them). XPBD constraints with compliance 0
 * (rigid) or the given one, solved before the contacts each substep. */
typedef struct ak_rigid_joint_desc {
    ak_rigid_joint_type type;       /* 0 -> ball */
    uint32_t body_a, body_b;        /* body indices, different; either may be static */
    ak_vec3 anchor;                 /* world point where the bodies are joined */
    ak_vec3 axis;                   /* world: hinge axis, prismatic slide axis, ball's swing axis;
                                       zero -> (0, 0, 1) */
    ak_vec3 axis_b;                 /* world: the axis as body b carries it, when b's zero-swing
                                       pose differs from the built one (ball swing); zero -> axis */
    float angle_offset;             /* hinge: the built pose's angle (rad) in the limits' measure:
                                       the limits apply to angle + angle_offset; ball: the same for
                                       the twist; 0 -> as built is 0 */
    bool twist_limited;             /* ball: twist_lower <= twist about the axis <= twist_upper */
    float twist_lower, twist_upper; /* radians */
    bool limited;                   /* hinge: lower <= angle <= upper; prismatic: lower <= offset
                                       <= upper; ball: swing (angle between the bodies' axes) <= upper */
    float lower, upper;             /* radians (hinge, ball) or metres (prismatic), as built = 0 */
    float compliance;               /* m/N and rad/(N m) of every part of the joint; 0 -> rigid */
    bool drive;                     /* drive b's orientation relative to a towards drive_target */
    ak_quat drive_target;           /* b's orientation in a's frame (a^-1 b); zero -> as built */
    float drive_compliance; /* rad/(N m); 0 -> rigid (the drive then acts as a fixed joint) */
    float drive_damping;    /* 1/s: with a drive, each substep removes the fraction
                               min(drive_damping h, 1) of the bodies' relative angular velocity
                               (shared by their inverse inertias, so momentum is kept: a damped
                               spring that settles instead of ringing); 0 -> none */
} ak_rigid_joint_desc;

AK_DEFINE_SPAN(rigid_joint_desc, ak_rigid_joint_desc)

/* The most passes over a substep's contacts (ak_rigid_model_desc.contact_iterations and
 * velocity_iterations). */
#define AK_RIGID_MAX_CONTACT_ITERATIONS 64

typedef struct ak_rigid_model_desc {
    ak_rigid_body_desc_cspan bodies;  /* at least one (required) */
    ak_rigid_joint_desc_cspan joints; /* optional */
    float linear_damping;             /* 1/s: v *= 1 / (1 + h c) each substep; 0 -> none */
    float angular_damping;            /* 1/s: the same on angular velocity; 0 -> none */
    float contact_offset;      /* metres: contacts are found this far before touching; 0 -> 0.01 */
    float sleep_linear_speed;  /* m/s under which a body may sleep; 0 -> 0.05 */
    float sleep_angular_speed; /* rad/s under which a body may sleep; 0 -> 0.05 */
    float sleep_time;          /* seconds a group must stay slow before it sleeps; 0 -> 0.5 */
    uint32_t max_contacts;     /* contact points (and pairs) per step the scratch holds; 0 -> 16
                                  per body + 64; more are dropped and counted in
                                  out_dropped_contacts */
    float joint_tolerance;     /* metres and radians: each substep's joint sweeps after the
                                  contacts (up to eight) stop, chain by chain, once a sweep
                                  corrects no joint of the chain by more than this; 0 -> 1e-4.
                                  1e-3 makes 50 falling ragdolls at 10 substeps about 25% faster
                                  for about the same worst joint gap over the fall (3.7 mm) and
                                  at rest (0.08 against 0.10 mm after 5 s; docs/rigid.md) */
    bool contacts_after_joints; /* one more pass over each substep's contacts after its joint
                                   sweeps, along the normals only, on the poses the joints
                                   left (false: none, the joints are solved last). The sweeps
                                   pull limbs back into the ground at an impact: 50 ragdolls
                                   dropped 1 m sink 47 mm at 1 substep without it, 0.8 mm with
                                   it, for about 1% more time and a worst joint gap 1% (1
                                   substep) to 30% (2 substeps) wider; without joints it is a
                                   second contact iteration (docs/rigid.md) */
    uint32_t contact_iterations; /* passes over each substep's contacts in its position solve,
                                    1 to AK_RIGID_MAX_CONTACT_ITERATIONS; 0 -> 1. The first
                                    pass solves the normals and, pair by pair, static and
                                    torsional friction; each further one the normals only,
                                    on the same rows (a pile's weight reaches the ground that
                                    many layers sooner). The 20-layer pyramid at 2 substeps
                                    with 3 sinks 8.2 mm (23.6 with 1) for 13% more time; 4
                                    substeps with 1 sink 5.7 mm for 49% more (docs/rigid.md) */
    uint32_t velocity_iterations; /* passes over each substep's pressed contacts in its velocity
                                     solve, 1 to AK_RIGID_MAX_CONTACT_ITERATIONS; 0 -> 4. Each
                                     pass before the last sets the normal velocities only (the
                                     last adds dynamic friction). One pass hands a pile's
                                     velocities down one contact at a time and leaves a 20-layer
                                     pyramid at rest jittering at 0.03-0.08 m/s (about g h), so
                                     it never sleeps; 4 passes bring that to 0.005-0.016 m/s
                                     at 4 substeps for about 6% more time per pass
                                     (docs/rigid.md, "Fidelity at rest") */
} ak_rigid_model_desc;

/* The desc with zero defaults filled in (desc NULL -> every default; bodies copied, not checked;
 * the bodies' own defaults are filled by ak_rigid_model_create). */
AK_API ak_rigid_model_desc ak_rigid_model_desc_resolved(const ak_rigid_model_desc* desc);

typedef struct ak_rigid_model ak_rigid_model;

/* Build a model. Returns AK_ERR_NULL_ARG (desc or out_model NULL), AK_ERR_EMPTY (no body),
 * AK_ERR_BAD_ARG (unknown shape, a radius or half extent <= 0 or a negative half height, a hull
 * with fewer than 4 or more than AK_RIGID_HULL_MAX_POINTS points or points that are all in one
 * plane (ak_rigid_hull_check says which), a heightfield with rows or cols < 2, too many samples,
 * spacing <= 0 or heights.count != rows * cols, a trimesh with no triangles, an index count
 * that is not a multiple of 3 or too many triangles, a compound with no or too many children or
 * a child that is not a sphere, box, capsule or hull), AK_ERR_NULL_ARG (a hull's, mesh's or
 * compound's array NULL with a count), AK_ERR_BAD_INDEX (a trimesh index >= vertices.count), a
 * negative density, mass, friction other than AK_RIGID_FRICTIONLESS, damping, offset, joint
 * tolerance or sleep value, restitution outside [0, 1], more than 2^24 bodies, contact_iterations
 * or velocity_iterations over AK_RIGID_MAX_CONTACT_ITERATIONS, an allocator with
 * only one function), AK_ERR_BAD_INDEX (a joint's body out of range, or both the same),
 * AK_ERR_BAD_ARG (unknown joint type, lower > upper, negative compliance), AK_ERR_BAD_DATA (a
 * non-finite value), AK_ERR_NO_MEMORY. *out_model is NULL on failure. */
AK_API ak_result ak_rigid_model_create(const ak_rigid_model_desc* desc, const ak_allocator* alloc,
                                       ak_rigid_model** out_model);
/* Free a model; NULL is a no-op. */
AK_API void ak_rigid_model_destroy(ak_rigid_model* model);

/* Whether points make a valid hull (as ak_rigid_model_create builds it): AK_OK, AK_ERR_NULL_ARG
 * (points.ptr NULL with a count), AK_ERR_BAD_DATA (a non-finite point), AK_ERR_BAD_ARG (fewer
 * than 4 or more than AK_RIGID_HULL_MAX_POINTS points, all on a line or in a plane, or too
 * nearly so for a valid hull), AK_ERR_NO_MEMORY; *out_problem (may be NULL) gets a static
 * message saying what is wrong ("" on success). */
AK_API ak_result ak_rigid_hull_check(ak_vec3_cspan points, const char** out_problem);

/* Number of joints (0 for NULL). */
AK_API size_t ak_rigid_joint_count(const ak_rigid_model* model);
/* How far joint i is from satisfied in a state: *out_gap the distance between its anchors (m,
 * prismatic: off the axis), *out_limit_excess how far its angle or offset is outside its limits
 * (rad or m, 0 when inside or unlimited). AK_ERR_NULL_ARG, AK_ERR_BAD_INDEX, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_rigid_joint_error(const ak_rigid_model* model, size_t joint_index,
                                      ak_vec3_cspan positions, ak_quat_cspan orientations,
                                      float* out_gap, float* out_limit_excess);

/* Number of bodies (0 for NULL). */
AK_API size_t ak_rigid_body_count(const ak_rigid_model* model);
/* Mass of a body in kg (INFINITY for a static one; 0 for NULL or an index out of range). */
AK_API float ak_rigid_body_mass(const ak_rigid_model* model, size_t body_index);
/* Principal moments of inertia (kg m^2) about the body's local axes (INFINITY for static; zero
 * for NULL or an index out of range). */
AK_API ak_vec3 ak_rigid_body_inertia(const ak_rigid_model* model, size_t body_index);
/* Pose of a body's shape frame (the frame a hull's points or a compound's children were given
 * in) in the body frame: identity for every other shape (see AK_RIGID_HULL); identity for NULL or an index out of
 * range. World pose of the shape frame = body pose * this. */
AK_API ak_transform ak_rigid_body_shape_frame(const ak_rigid_model* model, size_t body_index);
/* Volume (m^3) of a body's shape (0 for a plane, NULL or an index out of range). */
AK_API double ak_rigid_body_volume(const ak_rigid_model* model, size_t body_index);
/* A body's resolved desc (defaults filled in, orientation normalised, plane normal normalised);
 * a zeroed desc for NULL or an index out of range. */
AK_API ak_rigid_body_desc ak_rigid_body_get_desc(const ak_rigid_model* model, size_t body_index);

/* The descs' initial state into the spans (each count >= body count). AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_rigid_initial_state(const ak_rigid_model* model, ak_vec3_span out_positions,
                                        ak_quat_span out_orientations, ak_vec3_span out_velocities,
                                        ak_vec3_span out_angular_velocities);

/* Kinetic plus gravitational potential energy (J) of a state, -g.x m summed over dynamic bodies. */
AK_API double ak_rigid_energy(const ak_rigid_model* model, ak_vec3 gravity, ak_vec3_cspan positions,
                              ak_quat_cspan orientations, ak_vec3_cspan velocities,
                              ak_vec3_cspan angular_velocities);

/* World angular momentum (kg m^2/s) of one body about its centre of mass: R I R^T w. */
AK_API ak_vec3 ak_rigid_angular_momentum(const ak_rigid_model* model, size_t body_index,
                                         ak_quat orientation, ak_vec3 angular_velocity);

/* ---- ragdolls ------------------------------------------------------------------------- */

struct ak_skeleton;

/* How one skeleton joint maps onto the ragdoll's bodies. */
typedef struct ak_rigid_ragdoll_bone {
    int32_t body;     /* index into the model's bodies (body_offset included), or -1 for
                         a joint without a body (a leaf: it keeps its local transform) */
    ak_vec3 offset;   /* the joint's position in its body's frame (m) */
    ak_quat rotation; /* the joint's model rotation in its body's frame */
} ak_rigid_ragdoll_bone;

AK_DEFINE_SPAN(rigid_ragdoll_bone, ak_rigid_ragdoll_bone)

typedef struct ak_rigid_ragdoll_desc {
    const struct ak_skeleton* skeleton; /* required */
    ak_transform_cspan local_pose;      /* the start pose, local transforms (required) */
    ak_transform_cspan previous_pose;   /* optional: the pose `previous_dt` earlier, for the
                                           bodies' start velocities; empty -> at rest */
    float previous_dt;                  /* seconds; > 0 when previous_pose is given */
    ak_mat4 root;                       /* world transform above the skeleton; zero -> identity */
    uint32_t body_offset;               /* index the ragdoll's first body will have */
    float radius_scale;                 /* capsule radius / bone length; 0 -> 0.2 */
    float max_radius;                   /* metres; 0 -> 0.1 */
    float density;                      /* kg/m^3; 0 -> 1000 */
    float friction;                     /* 0 -> 0.5 */
    uint32_t collision_group;           /* the limbs' group (no self-collision); 0 -> 1 */
    float free_cone_angle;              /* radians: a free joint (glTF's joints have no type)
                                           becomes a ball whose bone may swing this far from its
                                           rest direction; 0 -> unlimited */
    /* Optional: a skinned mesh (a glTF skin and one of its meshes), so each capsule is fitted
     * to the vertices its bone carries instead of sized from radius_scale (see
     * ak_rigid_ragdoll_build). All empty -> no skin. */
    ak_vec3_cspan skin_positions;      /* bind-pose vertices, the mesh's model space */
    ak_u16_cspan skin_joints;          /* [vertex count * skin_influence_count] skin slots */
    ak_f32_cspan skin_weights;         /* the same layout */
    uint32_t skin_influence_count;     /* influences per vertex, 1..8 with a skin */
    ak_i32_cspan skin_slot_joints;     /* per slot: the skeleton joint it names */
    ak_mat4_cspan skin_inverse_binds;  /* per slot: its inverse bind matrix */
    float skin_min_weight;             /* a vertex belongs to its heaviest bone when that weight
                                          is >= this; 0 -> 0.5 */
    uint32_t skin_min_vertices;        /* fewer vertices than this on a bone -> radius_scale's
                                          capsule; 0 -> 8 */
    /* Powered ragdoll: every ball and hinge joint gets a drive towards the start pose (set
     * each step's targets from an animation with ak_rigid_ragdoll_drive_targets and the step
     * job's drive_targets, so the character follows the clip, is knocked off it by a hit and
     * comes back). A joint desc's drive_compliance may be changed per joint after the build. */
    bool powered;
    float drive_compliance;            /* rad/(N m) of every drive; 0 -> rigid (the clip is
                                          played exactly; only the root body reacts) */
    float drive_damping;               /* 1/s of every drive (ak_rigid_joint_desc); 0 -> none */
} ak_rigid_ragdoll_desc;

/* Bodies and joints a ragdoll of this skeleton has: one capsule per joint with children (from
 * the joint to the mean of its children's positions), one joint per such body whose joint has
 * a parent. 0 for NULL. */
AK_API size_t ak_rigid_ragdoll_body_count(const struct ak_skeleton* skeleton);
AK_API size_t ak_rigid_ragdoll_joint_count(const struct ak_skeleton* skeleton);

/* Build a ragdoll's body and joint descs (to put in an ak_rigid_model_desc, after body_offset
 * other bodies) and the joint-to-body map. Skeleton joint types become rigid joints: hinge ->
 * hinge with its limits, ball -> ball with its cone, free -> ball (coned by free_cone_angle),
 * prism -> prismatic; limits are taken relative to the skeleton's rest pose as the skeleton
 * measures them. With a skin, each body's capsule is fitted to the vertices whose heaviest
 * weight (>= skin_min_weight) is its bone's or a leaf child's, posed rigidly with their joint
 * at the start pose: radius = the mean plus one standard deviation of their distances from
 * the bone's line, and the capsule spans their extent along the bone (so the body's centre
 * may move off the bone's middle). Sizes: out_bodies >= body
 * count, out_joints >= joint count, out_bones >= skeleton joint count. Returns
 * AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_ARG (previous_pose without previous_dt > 0,
 * negative sizes or angle, a skin with a span missing or an influence count outside 1..8),
 * AK_ERR_BAD_INDEX (a skin slot or slot joint out of range), AK_ERR_BAD_DATA (a non-finite
 * pose, skin position, weight or matrix). */
AK_API ak_result ak_rigid_ragdoll_build(const ak_rigid_ragdoll_desc* desc,
                                        ak_rigid_body_desc_span out_bodies,
                                        ak_rigid_joint_desc_span out_joints,
                                        ak_rigid_ragdoll_bone_span out_bones);

/* A powered ragdoll's drive targets for a pose (an animation's local pose at the current
 * time), one per ragdoll joint in the order of ak_rigid_ragdoll_build's out_joints: the
 * orientation of each joint's body relative to its parent's body when the skeleton is in
 * local_pose (the rotation part of the local transforms; translations and scale are ignored).
 * Put them at the ragdoll's joints' places in the step job's drive_targets. Sizes: bones and
 * local_pose >= skeleton joint count, out_targets >= ak_rigid_ragdoll_joint_count.
 * AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_INDEX (a bone's parent without a body: bones
 * not from this skeleton's build), AK_ERR_BAD_DATA (a non-finite rotation). */
AK_API ak_result ak_rigid_ragdoll_drive_targets(const struct ak_skeleton* skeleton,
                                                ak_rigid_ragdoll_bone_cspan bones,
                                                ak_transform_cspan local_pose,
                                                ak_quat_span out_targets);

/* The ragdoll's bodies written back as a skeleton pose: local transforms (scale from
 * fallback_pose) so that skinning and export work unchanged. Joints without a body keep
 * fallback_pose's local transform. root as in the desc. Sizes >= skeleton joint count.
 * AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_INDEX (a bone's body out of the state). */
AK_API ak_result ak_rigid_ragdoll_pose(const struct ak_skeleton* skeleton,
                                       ak_rigid_ragdoll_bone_cspan bones, ak_mat4 root,
                                       ak_vec3_cspan positions, ak_quat_cspan orientations,
                                       ak_transform_cspan fallback_pose,
                                       ak_transform_span out_local_pose);

/* ---- meshes of the bodies (drawing, baking, colliders for other simulations) ----------- */

/* Vertices and indices (3 per triangle) of a shape's mesh: a sphere or capsule as an 8 x 16
 * latitude-longitude grid (capsules with a doubled equator), a box's 6 faces (24 vertices), a
 * plane as a square (4), a heightfield's grid (a vertex per sample, 2 triangles per cell), a
 * trimesh's triangles (3 vertices each); 0 for a hull or a compound (their faces and children
 * are built by the model: ak_rigid_body_mesh), for NULL or an unknown type. */
AK_API void ak_rigid_shape_mesh_size(const ak_rigid_shape* shape, size_t* out_vertex_count,
                                     size_t* out_index_count);
/* A shape's closed, outward-facing mesh (counter-clockwise seen from outside) in the body's
 * frame: vertices on the shape's surface (a sphere's and a capsule's inscribed in it), unit
 * normals, triangles; a plane is a square of half side plane_size (0 -> 10 m) in its own frame
 * (Y up); a heightfield is its grid split into triangles as the collisions split it (cell (i, j):
 * samples 00-01-11 and 00-11-10, counter-clockwise seen from +Y, normals by central
 * differences), open at its border; a trimesh is its own triangles, each with its face normal.
 * Sizes from ak_rigid_shape_mesh_size. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (type),
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_rigid_shape_mesh(const ak_rigid_shape* shape, float plane_size,
                                     ak_vec3_span out_positions, ak_vec3_span out_normals,
                                     ak_u32_span out_indices);
/* Vertices and indices of body i's mesh as ak_rigid_body_mesh writes it (0 for NULL or an index
 * out of range). */
AK_API void ak_rigid_body_mesh_size(const ak_rigid_model* model, size_t body_index,
                                    size_t* out_vertex_count, size_t* out_index_count);
/* Body i's mesh in its body frame (centre of mass, principal axes: world = pose * vertex): every
 * shape drawn as itself. Spheres, boxes, capsules, planes, heightfields and trimeshes as
 * ak_rigid_shape_mesh draws them; a hull as its convex polygon faces, each fanned into
 * triangles around its first vertex with its own vertices and the face's outward normal (so
 * the mesh is closed once equal positions are merged, and its vertices are the hull's); a
 * compound as each child's mesh placed by the child's pose. AK_ERR_NULL_ARG, AK_ERR_BAD_INDEX,
 * AK_ERR_BAD_ARG (plane_size negative or not finite), AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_rigid_body_mesh(const ak_rigid_model* model, size_t body_index,
                                    float plane_size, ak_vec3_span out_positions,
                                    ak_vec3_span out_normals, ak_u32_span out_indices);
/* Totals of ak_rigid_world_mesh: every body but the planes (0 for NULL). */
AK_API void ak_rigid_world_mesh_size(const ak_rigid_model* model, size_t* out_vertex_count,
                                     size_t* out_index_count);
/* Every body but the planes as one world-space triangle mesh at a state (body order, each
 * body's ak_rigid_body_mesh moved by its pose): to draw a scene, or to give cloth
 * (ak_cloth_collider_mesh) and particles (ak_particle_mesh) the bodies as a one-way collider
 * each step. Boxes, hulls, compounds of them, heightfields and trimeshes are exact; spheres and
 * capsules are inscribed polyhedra (at most 8% inside the true surface at 8 x 16).
 * AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_DATA (a non-finite state), AK_ERR_UNSUPPORTED
 * (more than 2^32 - 1 vertices: 32-bit indices cannot reach them). */
AK_API ak_result ak_rigid_world_mesh(const ak_rigid_model* model, ak_vec3_cspan positions,
                                     ak_quat_cspan orientations, ak_vec3_span out_positions,
                                     ak_vec3_span out_normals, ak_u32_span out_indices);

/* ---- the bodies as colliders of the fluid (one-way) ------------------------------------ */

/* Colliders and convex planes ak_rigid_fluid_colliders writes for a model: one collider per
 * sphere, box, capsule, plane, hull and heightfield body and per child of a compound; a hull's
 * collider takes one plane per face. Triangle meshes are not passed to the fluid. 0 for NULL. */
AK_API void ak_rigid_fluid_colliders_size(const ak_rigid_model* model, size_t* out_collider_count,
                                          size_t* out_plane_count);
/* The bodies at a state as the fluid's colliders (fluid.h), so a liquid collides one-way with
 * them: each step, write them at the bodies' current poses and velocities and pass them as the
 * fluid step job's colliders (after the rigid step, so the liquid is pushed out of where the
 * bodies now are):
 *     ak_rigid_step_run(&rigid_job);
 *     ak_rigid_fluid_colliders(model, x, q, v, w, (ak_fluid_collider_span){cols, nc},
 *                              (ak_vec4_span){planes, np}, &nc);
 *     fluid_job.colliders = (ak_fluid_collider_cspan){cols, nc};
 *     ak_fluid_step_run(&fluid_job);
 * A sphere becomes AK_FLUID_SPHERE, a capsule AK_FLUID_CAPSULE (its segment's ends), a box
 * AK_FLUID_BOX, a plane AK_FLUID_PLANE, a hull AK_FLUID_CONVEX (its faces' planes in its body
 * frame, written to out_planes, which the colliders point into: keep it alive while they are
 * used), a heightfield AK_FLUID_HEIGHTFIELD (pointing at the model's samples: keep the model
 * alive), a compound one of those per child, in body order (children in order). Each collider
 * carries its body's motion: velocity at its point a (v + w x (a - x)) and angular velocity w
 * (zero for static bodies). Sizes from ak_rigid_fluid_colliders_size; *out_collider_count (may
 * be NULL) gets the count written. AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_DATA (a
 * non-finite state). The fluid sees only the shapes: the bodies feel no force from the liquid. */
AK_API ak_result ak_rigid_fluid_colliders(const ak_rigid_model* model, ak_vec3_cspan positions,
                                          ak_quat_cspan orientations, ak_vec3_cspan velocities,
                                          ak_vec3_cspan angular_velocities,
                                          ak_fluid_collider_span out_colliders,
                                          ak_vec4_span out_planes, size_t* out_collider_count);

/* ---- a run baked as glTF node animation ------------------------------------------------ */

struct ak_scene;

typedef struct ak_rigid_bake_desc {
    const char* name;              /* scene, root node, meshes and clip name; NULL -> "rigid" */
    const ak_rigid_model* model;   /* required: the bodies' shapes */
    size_t frame_count;            /* required, 1 .. max_frames */
    const ak_vec3* positions;      /* required, [frame_count * body count], frame k first */
    const ak_quat* orientations;   /* required, the same layout */
    float frame_time;              /* required, > 0 seconds between frames */
    float plane_size;              /* half the side of the square drawn for a plane (m);
                                      0 -> 10 */
    size_t max_frames;             /* 0 -> AK_SCENE_BAKE_MAX_FRAMES (scene.h) */
    size_t memory_budget;          /* bytes; 0 -> AK_SCENE_BAKE_DEFAULT_BUDGET (scene.h) */
} ak_rigid_bake_desc;

/* Bake recorded frames of a run as an animated scene (io.h's ak_io_save writes it as glTF):
 * a root node named name and one child node "<name>_<i>" per body in body order, each
 * carrying its shape as a mesh in the body's frame (ak_rigid_body_mesh: a sphere or capsule
 * as a latitude-longitude grid, a box's 6 faces, a hull's faces, a compound's children, a
 * heightfield's or trimesh's triangles, a plane as a square around its point with Y along its
 * normal), rest transform = frame 0's pose; one clip named name with a LINEAR translation and
 * rotation channel per dynamic body keyed at every frame (rotations taken the short way from
 * the previous key), frame k at time k * frame_time. One frame, or only static bodies: no
 * clip. The bytes needed are estimated before anything is allocated. Returns AK_ERR_NULL_ARG,
 * AK_ERR_EMPTY (no frame), AK_ERR_BAD_ARG (frame_time, plane_size), AK_ERR_BAD_DATA (a
 * non-finite or zero pose: diag names frame and body), AK_ERR_UNSUPPORTED (over max_frames,
 * the memory budget, or 32000 bodies), AK_ERR_NO_MEMORY; *out_scene NULL on failure. */
AK_API ak_result ak_rigid_bake_scene(const ak_rigid_bake_desc* desc, const ak_allocator* alloc,
                                     struct ak_scene** out_scene, ak_diag* diag);

/* A ragdoll's recorded run as the skeleton's animation: the clip that plays, on the character
 * the ragdoll was built from, the pose ak_rigid_ragdoll_pose writes back at each frame (so the
 * skinned mesh moves as the bodies did when the character's scene, with this clip, is saved as
 * glTF). */
struct ak_clip;

typedef struct ak_rigid_bake_ragdoll_desc {
    const char* name;                   /* clip name; NULL -> "ragdoll" */
    const struct ak_skeleton* skeleton; /* required */
    ak_rigid_ragdoll_bone_cspan bones;  /* required: ak_rigid_ragdoll_build's map */
    ak_mat4 root;                       /* the world transform the character is drawn under;
                                           zero -> identity (the root joints then carry the
                                           ragdoll's world pose) */
    ak_transform_cspan fallback_pose;   /* required: joints without a body keep these */
    size_t body_count;                  /* bodies per frame in positions and orientations */
    size_t frame_count;                 /* required, 1 .. max_frames */
    const ak_vec3* positions;           /* required, [frame_count * body_count] */
    const ak_quat* orientations;        /* required, the same layout */
    float frame_time;                   /* required, > 0 */
    size_t max_frames;                  /* 0 -> AK_SCENE_BAKE_MAX_FRAMES (scene.h) */
    size_t memory_budget;               /* 0 -> AK_SCENE_BAKE_DEFAULT_BUDGET (scene.h) */
} ak_rigid_bake_ragdoll_desc;

/* Build the clip: a LINEAR translation and rotation channel for every joint of the skeleton,
 * keyed at every frame with ak_rigid_ragdoll_pose's local transforms (rotations taken the short
 * way from the previous key), frame k at time k * frame_time. Returns AK_ERR_NULL_ARG,
 * AK_ERR_EMPTY, AK_ERR_BAD_ARG (frame_time), AK_ERR_SPAN_SMALL (bones or fallback_pose shorter
 * than the skeleton), AK_ERR_BAD_INDEX (a bone's body not below body_count), AK_ERR_BAD_DATA (a
 * non-finite pose: diag names the frame), AK_ERR_UNSUPPORTED (over max_frames or the budget),
 * AK_ERR_NO_MEMORY; *out_clip NULL on failure (free a clip with ak_clip_destroy). */
AK_API ak_result ak_rigid_bake_ragdoll_clip(const ak_rigid_bake_ragdoll_desc* desc,
                                            const ak_allocator* alloc, struct ak_clip** out_clip,
                                            ak_diag* diag);

/* ---- step ------------------------------------------------------------------------------ */

#define AK_RIGID_MAX_THREADS 64

/* One entry of a step's contact anchor cache (ak_rigid_step_job.contact_anchors): a pair of
 * touching bodies whose static friction held at the end of the step (box and plane pairs: flat
 * faces and corners), keyed by (body_a, body_b) with body_a < body_b. `drift` is how far body_a's
 * contact anchor has slipped along the contact plane from body_b's since the contact began,
 * which the step's static friction has not yet undone (what later pairs of the sequential solve
 * moved after a pair's friction ran); `normal` is the contact normal (from body_b towards
 * body_a). Both are in body_b's frame, so the entry turns with the pair. The next step adds the
 * drift to the slip its static friction undoes: the anchors persist from step to step (Mueller et
 * al. 2020, 3.5), and a pile does not creep by what each step leaves over. Written by
 * ak_rigid_step_run; callers only allocate, zero the count, and keep the array between steps. */
typedef struct ak_rigid_contact_anchor {
    uint32_t body_a, body_b; /* body_a < body_b */
    ak_vec3 drift;           /* metres, body_b's frame */
    ak_vec3 normal;          /* unit, body_b's frame */
    float twist;             /* radians body_a turned about the normal against body_b over the
                                step (reported; not read back: the drift at the centre of
                                pressure already holds the twist's motion there) */
} ak_rigid_contact_anchor;

AK_DEFINE_SPAN(rigid_contact_anchor, ak_rigid_contact_anchor)

typedef struct ak_rigid_step_job {
    const ak_rigid_model* model; /* required */
    float dt;                    /* seconds, > 0 (required) */
    uint32_t substeps;           /* XPBD substeps per step; 0 -> 10; <= 1000 */
    ak_vec3 gravity;             /* m/s^2, world (zero is a real choice: no gravity) */
    uint32_t thread_count;       /* <= AK_RIGID_MAX_THREADS; 0 -> 1. Shares out the islands
                                    (see the header's opening); the same bits for any value */
    /* State, one element per body, read and written (world space). */
    ak_vec3_span positions;
    ak_quat_span orientations;
    ak_vec3_span velocities;
    ak_vec3_span angular_velocities;
    ak_f32_span sleep_timers; /* optional: seconds each body has been slow (state, start at
                                 0); empty -> bodies never sleep */
    ak_u8_span scratch;       /* >= ak_rigid_step_scratch_size(job) bytes */
    ak_quat_cspan drive_targets; /* optional, one per joint (model order): the drive target of
                                    each joint with `drive` for this step, in place of its
                                    desc's (a powered ragdoll's animation: see
                                    ak_rigid_ragdoll_drive_targets; normalised here); entries
                                    of joints without a drive are ignored; empty -> the descs' */
    /* Optional persistent contacts (state, kept by the caller between steps; see
       ak_rigid_contact_anchor): contact_anchors holds up to its count entries, of which
       *contact_anchor_count (start at 0) are valid, sorted by (body_a, body_b); each step reads
       them and writes the new ones. About one per touching pair of boxes or planes: 4 per body
       is plenty for piles; pairs beyond the room get none (their friction then acts as without
       the cache). Empty -> no anchors carried between steps (each step's static friction undoes
       only that step's slip). contact_anchor_count is required when contact_anchors is given.
       After moving bodies by hand (a teleport, a reset), set *contact_anchor_count to 0. */
    ak_rigid_contact_anchor_span contact_anchors;
    uint32_t* contact_anchor_count;
    /* Outputs (optional). */
    float* out_max_penetration;     /* metres: deepest contact after the step's last solve */
    uint32_t* out_contact_count;    /* contact points of the last substep */
    uint32_t* out_dropped_contacts; /* contact points (and pairs) over max_contacts: those of box
                                       and plane pairs once per step, the others summed over
                                       substeps */
} ak_rigid_step_job;

/* Bytes of scratch a step needs (0 for a NULL job or model). */
AK_API size_t ak_rigid_step_scratch_size(const ak_rigid_step_job* job);

/* First rule the job breaks: AK_ERR_NULL_ARG (job or model NULL, drive_targets counted but
 * NULL), AK_ERR_BAD_ARG (dt <= 0 or not finite, substeps > 1000, thread_count >
 * AK_RIGID_MAX_THREADS, non-finite gravity), AK_ERR_SPAN_SMALL (a state span shorter than the
 * body count, sleep_timers neither empty nor long enough, drive_targets neither empty nor one
 * per joint, scratch too small), AK_ERR_BAD_DATA (a non-finite state value, a non-finite or
 * zero drive target, a contact anchor count over its span or an anchor entry not finite, not
 * naming two bodies in order, or out of (body_a, body_b) order); AK_ERR_NULL_ARG also for
 * contact_anchors counted without a pointer or without contact_anchor_count. */
AK_API ak_result ak_rigid_step_validate(const ak_rigid_step_job* job);

/* Advance the state by dt. Validates first and writes nothing on failure. Returns AK_ERR_BAD_DATA
 * (and leaves the state as it was) when the step produced a non-finite value, so a caller can
 * name the step that blew up. */
AK_API ak_result ak_rigid_step_run(const ak_rigid_step_job* job);

/* ---- scene files and presets ------------------------------------------------------------ */
/* A rigid-body scene: the JSON format of `animkit rigid SCENE.json` (docs/rigid.md lists every
 * key, its unit, its default and its range) or a preset, over the defaults:
 *     ak_rigid_scene sc;
 *     ak_diag diag;
 *     ak_rigid_scene_defaults(&sc);                          // or ak_rigid_scene_preset(...)
 *     if (ak_rigid_scene_load_file("stack.json", &sc, &diag) != AK_OK) puts(diag.message);
 *     ... ak_rigid_scene_run_* (below), or ak_rigid_model_create with sc.model, sc.bodies and
 *         sc.joints, then sc.steps steps of sc.dt with sc.substeps and sc.gravity ...
 *     ak_rigid_scene_free(&sc); */

/* Budgets that bound a hostile scene's memory (checked before anything is allocated). */
#define AK_RIGID_SCENE_MAX_BODIES 100000u
#define AK_RIGID_SCENE_MAX_JOINTS 100000u
#define AK_RIGID_SCENE_MAX_POINTS 1000000u /* hull points and mesh vertices, all bodies */
#define AK_RIGID_SCENE_MAX_CHILDREN 100000u /* compound children, all bodies */
#define AK_RIGID_SCENE_MAX_STEPS 1000000L
#define AK_RIGID_SCENE_MAX_SUBSTEPS 1000L
#define AK_RIGID_SCENE_MAX_FILE_SIZE ((size_t)64 << 20)
/* The names ak_rigid_scene_preset knows (also as a list: ak_rigid_scene_preset_names). */
#define AK_RIGID_SCENE_PRESETS "stack, pyramid, dominoes, avalanche, ragdoll, incline"

/* A loaded scene; it owns bodies and joints (malloc). */
typedef struct ak_rigid_scene {
    ak_rigid_body_desc* bodies;  /* [body_count], scene order */
    size_t body_count;
    ak_rigid_joint_desc* joints; /* [joint_count]; body indices into bodies */
    size_t joint_count;
    ak_vec3* points;             /* [point_count]: the hulls' points and the meshes' vertices
                                    (bodies' shape.points / shape.vertices point here) */
    size_t point_count, point_cap;
    float* heights;              /* [height_count]: the heightfields' samples */
    size_t height_count, height_cap;
    uint32_t* indices;           /* [index_count]: the triangle meshes' indices */
    size_t index_count, index_cap;
    struct ak_rigid_child* children; /* [child_count]: the compounds' children */
    size_t child_count, child_cap;
    ak_rigid_model_desc model;   /* damping and contact offset; its bodies and joints spans are
                                    left empty (ak_rigid_scene_run_init fills a copy) */
    ak_vec3 gravity;             /* m/s^2; default (0, -9.81, 0) */
    float dt;                    /* seconds per step; default 1/60 */
    long steps;                  /* default 240 */
    uint32_t substeps;           /* default 20 */
    uint32_t thread_count;       /* default 1 */
    bool sleep;                  /* bodies may fall asleep; default true */
    /* The ragdoll preset's character (empty otherwise, and after a file is loaded over it), so
     * a run can be shown as the character (ak_rigid_bake_ragdoll_clip): the builtin model
     * (ak_builtin_create(ragdoll_character, {.cell_size = ragdoll_cell_size})) whose skeleton
     * the ragdoll was built from, its bone map (body indices into bodies) and root, and its
     * start pose (local transforms). Owned (malloc), freed by ak_rigid_scene_free. */
    char ragdoll_character[32];
    float ragdoll_cell_size;
    ak_rigid_ragdoll_bone* ragdoll_bones; /* [ragdoll_bone_count] */
    ak_transform* ragdoll_pose;           /* [ragdoll_bone_count] */
    size_t ragdoll_bone_count;            /* the skeleton's joint count; 0 -> no character */
    ak_mat4 ragdoll_root;
} ak_rigid_scene;

/* The defaults of every key, no bodies, no joints (the scene without a file); owns nothing. */
AK_API void ak_rigid_scene_defaults(ak_rigid_scene* scene);
/* Parse bytes[0, size) (strict JSON) OVER the scene already in *scene, which must hold
 * ak_rigid_scene_defaults or a preset (keys absent from the file keep its values; "bodies" is
 * required, so the file's bodies and joints replace the scene's). name (NULL -> "(scene)") starts
 * every message. Returns AK_OK, or AK_ERR_PARSE / AK_ERR_NULL_ARG with, when out_diag is not NULL,
 * the one line "NAME: key.path: problem" in out_diag->message, and no bodies or joints left in
 * *scene. In every case free *scene with ak_rigid_scene_free afterwards. */
AK_API ak_result ak_rigid_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                           ak_rigid_scene* scene, ak_diag* out_diag);
/* Read the file at path (at most AK_RIGID_SCENE_MAX_FILE_SIZE bytes) and parse it over *scene as
 * ak_rigid_scene_load_bytes does; AK_ERR_IO when it cannot be read or is too big. */
AK_API ak_result ak_rigid_scene_load_file(const char* path, ak_rigid_scene* scene, ak_diag* out_diag);
/* The defaults, then the preset name (AK_RIGID_SCENE_PRESETS; docs/rigid.md describes them):
 * "stack" (ten 1 m boxes), "pyramid" (20 layers, 210 boxes), "dominoes" (20, the first pushed),
 * "avalanche" (200 spheres, boxes and capsules down a 30 degree slope), "ragdoll"
 * (builtin:humanoid dropped mid-walk), "incline" (a box that slides and one that stays on a 30
 * degree slope). *out_scene is overwritten without being freed (pass a new or freed scene).
 * AK_ERR_NOT_FOUND for another name (the scene then holds the defaults), AK_ERR_NO_MEMORY, or the
 * error building the ragdoll's character. */
AK_API ak_result ak_rigid_scene_preset(const char* name, ak_rigid_scene* out_scene, ak_diag* out_diag);
/* The preset names as a NULL-terminated list (static storage); *out_count (may be NULL) gets
 * their number. */
AK_API const char* const* ak_rigid_scene_preset_names(size_t* out_count);
/* Free the arrays (NULL: no-op; safe twice); the other fields keep their values. */
AK_API void ak_rigid_scene_free(ak_rigid_scene* scene);

/* ---- running a scene ---------------------------------------------------------------------- */
/* Step a loaded scene as `animkit rigid` does, so that C and Python reproduce the command's
 * output (the model built from the scene, its initial state, sleep timers when scene->sleep):
 *     ak_rigid_scene_run run;
 *     if (ak_rigid_scene_run_init(&run, &sc, "stack", &diag) == AK_OK)
 *         while (run.step_index < sc.steps && ak_rigid_scene_run_step(&run) == AK_OK) {}
 *     ... run.positions[i], run.orientations[i], ak_rigid_scene_run_energy(&run) ...
 *     ak_rigid_scene_run_free(&run); */
typedef struct ak_rigid_scene_run {
    ak_rigid_model* model; /* built from the scene (owned by the run) */
    size_t body_count;
    ak_vec3* positions;    /* [body_count]: the current state, world space */
    ak_quat* orientations;
    ak_vec3* velocities;
    ak_vec3* angular_velocities;
    ak_vec3 gravity;       /* the scene's */
    float max_penetration; /* metres, after the last step (0 before the first) */
    long step_index;       /* steps taken */
    double time;           /* seconds simulated: step_index * dt */
    uint64_t dropped_contacts; /* contact points (and pairs) over max_contacts, summed over the
                                  steps (out_dropped_contacts): 0 unless the scene's
                                  max_contacts is too small for it */
    long dropped_first_step;   /* the first step (1-based) that dropped any, 0 when none did */
    ak_rigid_step_job job; /* points into the arrays above */
    /* private */
    float* sleep_timers;
    uint32_t dropped_last;
    ak_rigid_contact_anchor* anchors; /* 4 per body: the step's persistent contacts */
    uint32_t anchor_count;
} ak_rigid_scene_run;

/* Build the model and the initial state and validate the step job. The scene may be freed
 * afterwards (the model copies what it needs). AK_OK, or the failing code with "NAME: problem" in
 * out_diag (name NULL -> "scene"); free with ak_rigid_scene_run_free either way. */
AK_API ak_result ak_rigid_scene_run_init(ak_rigid_scene_run* run, const ak_rigid_scene* scene,
                                         const char* name, ak_diag* out_diag);
/* One step of the scene's dt. AK_ERR_BAD_DATA: the step blew up (a non-finite state; the state
 * is left as it was and step_index does not advance: lower dt or raise substeps). */
AK_API ak_result ak_rigid_scene_run_step(ak_rigid_scene_run* run);
/* Kinetic plus gravitational potential energy of the current state (J), as ak_rigid_energy. */
AK_API double ak_rigid_scene_run_energy(const ak_rigid_scene_run* run);
/* Free the model and the arrays (safe on a zeroed or failed run, and twice). */
AK_API void ak_rigid_scene_run_free(ak_rigid_scene_run* run);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_RIGID_H */
