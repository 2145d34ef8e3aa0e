/* animkit deform: expressive deformers from the principles of animation.
 *
 * What it does:
 *   - squash and stretch: scale s along an axis and 1/sqrt(s) across it about a centre, so
 *     the determinant is s * (1/sqrt(s))^2 = 1 and volume is preserved exactly; driven by a
 *     parameter, or automatically from a moving point's velocity and acceleration
 *     (ak_squash_tracker, caller-owned state), or by the ready-made bouncing ball
 *     (ak_bounce_sample: position, axis and stretch of a ball at time t);
 *   - bend: the segment [0, L] of an axis is wrapped onto a circular arc turning through an
 *     angle theta towards a bend direction (beyond L the shape continues rigidly);
 *   - twist: rotation about the axis growing linearly from 0 at the origin to an angle at L;
 *   - follow-through ("jiggle"): a spring-damper per chosen joint that lags behind and
 *     overshoots the animated motion (tails, ears, antennae, bellies). It integrates with a
 *     fixed substep whatever the frame rate, and moves the jiggled joints' descendants along.
 * Deformers work on caller-owned position/normal arrays (model space, or any space the
 * deformer's origin and axis are given in); normals get the inverse-transpose of the local
 * Jacobian, renormalised.
 *
 * What it does NOT do: skinning (skin.h), collisions, or choose which joints jiggle.
 *
 * Usage (a bouncing ball, then a jiggling tail):
 *     ak_bounce_desc ball = { .height = 1.5f, .radius = 0.25f, .forward_speed = 1.0f };
 *     ak_bounce_state b = ak_bounce_sample(&ball, t);     // draw a unit sphere with b.model
 *
 *     ak_jiggle_joint tail[3] = { {.joint = 5, .tip = {0, 0, -0.2f}}, {.joint = 6, ...}, ... };
 *     ak_jiggle_state state[3] = {0};                     // zero -> starts at rest
 *     ak_jiggle_job job = {
 *         .params = { .stiffness = 150.0f, .damping = 10.0f, .gravity = {0, -9.81f, 0} },
 *         .parents = ak_skeleton_parents(skeleton),
 *         .joints = tail, .joint_count = 3, .states = AK_SPAN(state),
 *         .model = { animated, joint_count },             // FK output of the animated pose
 *         .out_model = { jiggled, joint_count }, .dt = frame_dt,
 *     };
 *     ak_result r = ak_jiggle_run(&job);                  // skin with `jiggled`
 *
 * Ownership and threading: no objects; every state struct is owned by the caller and touched
 * only by the call it is passed to. Calls with distinct outputs and states may run in
 * parallel. Nothing keeps a caller pointer after a call.
 */
#ifndef ANIMKIT_DEFORM_H
#define ANIMKIT_DEFORM_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- squash & stretch, bend, twist ----------------------------------------------------- */

typedef enum ak_deformer_type {
    AK_DEFORMER_SQUASH = 0, /* default: volume-preserving scale along axis */
    AK_DEFORMER_BEND,       /* arc bend of [0, length] along axis towards bend_direction */
    AK_DEFORMER_TWIST,      /* rotation about axis, 0 at origin to amount at length */
    AK_DEFORMER_TYPE_COUNT
} ak_deformer_type;

typedef struct ak_deformer {
    ak_deformer_type type;  /* 0 -> AK_DEFORMER_SQUASH */
    ak_vec3 origin;         /* fixed point (squash centre; start of the bend/twist region) */
    ak_vec3 axis;           /* direction, normalised here; zero -> (0, 1, 0) */
    ak_vec3 bend_direction; /* bend only: the side the axis curls towards; its part along axis
                               is removed; zero (or parallel to axis) -> any perpendicular */
    float amount;           /* squash: stretch s > 0 along axis (0 -> 1, no change; s < 1
                               squashes); bend/twist: angle in radians (0 is no change) */
    float length;           /* bend/twist: length L of the deformed region, > 0; 0 -> 1 */
} ak_deformer;

/* The deformer with defaults filled in (axis unit, bend_direction unit and perpendicular,
 * amount 0 -> 1 for squash, length 0 -> 1). Non-finite fields are not repaired here; the
 * job rejects them. */
AK_API ak_deformer ak_deformer_resolved(ak_deformer deformer);

/* The squash/stretch matrix about centre: T(c) (s a a^T + (I - a a^T)/sqrt(s)) T(-c).
 * Determinant 1. axis zero -> (0,1,0); s <= 0 or non-finite -> identity. */
AK_API ak_mat4 ak_squash_matrix(ak_vec3 center, ak_vec3 axis, float stretch);

/* One point through one deformer (resolved first). Invalid deformers (non-finite fields, squash
 * amount < 0) return p unchanged. */
AK_API ak_vec3 ak_deformer_apply_point(const ak_deformer* deformer, ak_vec3 p);

/* Deform points (and optionally normals) through a stack of deformers, applied in order. */
typedef struct ak_deform_job {
    const ak_deformer* deformers; /* required, deformer_count entries */
    size_t deformer_count;        /* required, > 0 */
    ak_vec3_cspan positions;      /* required, count > 0 */
    ak_vec3_cspan normals;        /* same count; needed only with out_normals */
    ak_vec3_span out_positions;   /* required, count >= positions.count; may be positions */
    ak_vec3_span out_normals;     /* optional, count >= positions.count; may be normals */
} ak_deform_job;

/* AK_ERR_NULL_ARG (deformers, positions or out_positions empty, out_normals set without
 * normals), AK_ERR_BAD_ARG (normals.count != positions.count, a deformer of unknown type,
 * non-finite field, squash amount < 0, bend/twist length < 0), AK_ERR_SPAN_SMALL.
 * A zero-initialised job gives AK_ERR_NULL_ARG. */
AK_API ak_result ak_deform_validate(const ak_deform_job* job);
/* Validate, then deform. Bend: points past the centre of curvature (w > 1/curvature) fold
 * over; their normals use a clamped Jacobian and stay finite. Writes nothing on failure. */
AK_API ak_result ak_deform_run(const ak_deform_job* job);

/* ---- automatic squash & stretch from motion --------------------------------------------- */

typedef struct ak_squash_tracker_desc {
    float speed_gain;       /* stretch added per unit speed (1/(m/s)), along the velocity */
    float accel_gain;       /* squash per unit acceleration (1/(m/s^2)), along the acceleration:
                               s = 1/(1 + accel_gain max(|a - gravity| - accel_dead_zone, 0)) */
    ak_vec3 gravity;        /* acceleration that does not squash (free fall); zero -> none. A point
                               at rest then carries its weight, |a - gravity| = |gravity|: raise
                               accel_dead_zone above it to keep resting points round */
    float accel_dead_zone;  /* m/s^2 of |a - gravity| ignored (impacts far exceed it); 0 -> none */
    float min_stretch;      /* clamp; 0 -> 0.5 */
    float max_stretch;      /* clamp; 0 -> 2 */
    float response_time;    /* seconds to close 63% of the gap to the target stretch; 0 -> instant */
} ak_squash_tracker_desc;

/* The desc with its zero defaults filled in (min_stretch 0 -> 0.5, max_stretch 0 -> 2); NULL
 * gives every default. Other fields are copied unchanged (the update checks them). */
AK_API ak_squash_tracker_desc ak_squash_tracker_desc_resolved(const ak_squash_tracker_desc* desc);

/* Caller-owned state; zero-initialised means "no samples yet". */
typedef struct ak_squash_tracker {
    ak_vec3 prev_position;  /* last sample */
    ak_vec3 prev_velocity;  /* finite-difference velocity at the last sample */
    ak_vec3 axis;           /* current squash axis (unit) */
    float log_stretch;      /* current ln(s), smoothed */
    uint32_t sample_count;  /* samples seen (saturates) */
} ak_squash_tracker;

/* Feed the point's position at the end of a step of dt seconds and get a squash deformer
 * centred on it. Velocity and acceleration are finite differences (velocity zero at the first
 * sample, acceleration ignored for the first two). The target stretch is the larger deformation (in |ln s|) of the speed
 * stretch 1 + speed_gain |v| along v and the acceleration squash along a - gravity; it is
 * clamped, then approached with the response time. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG
 * (dt <= 0 or non-finite, a negative or non-finite gain, time, dead zone or clamp, resolved
 * min_stretch > max_stretch),
 * AK_ERR_BAD_DATA (non-finite position); the tracker is unchanged on failure. */
AK_API ak_result ak_squash_tracker_update(ak_squash_tracker* tracker, const ak_squash_tracker_desc* desc,
                                          ak_vec3 position, float dt, ak_deformer* out_deformer);

/* ---- the bouncing ball ------------------------------------------------------------------- */

typedef struct ak_bounce_desc {
    float height;           /* apex height of the ball's bottom above the floor (m); 0 -> 1 */
    float radius;           /* rest radius (m); 0 -> 0.25 */
    float gravity;          /* m/s^2, downwards (-Y); 0 -> 9.81 */
    float contact_time;     /* seconds the ball stays on the floor squashing; 0 -> 0.1 */
    float squash;           /* stretch at the deepest squash, [0.05, 1]; 0 -> 0.6 (1 = rigid) */
    float stretch_per_speed;/* in flight s = 1 + this * speed, (1/(m/s)); 0 -> 0.04 */
    float forward_speed;    /* constant +X speed (m/s); 0 -> bounces in place */
    ak_vec3 start;          /* floor point under the ball at t = 0 (the floor is y = start.y) */
} ak_bounce_desc;

typedef struct ak_bounce_state {
    ak_vec3 center;         /* centre of the ball */
    ak_vec3 velocity;       /* of the centre of mass (m/s); zero during contact */
    ak_vec3 axis;           /* squash/stretch axis (unit): the velocity in flight, +Y in contact */
    float stretch;          /* s along axis (< 1 in contact, > 1 in flight) */
    bool in_contact;        /* true while on the floor */
    ak_mat4 model;          /* unit sphere at the origin -> deformed ball: T(center) Squash R */
} ak_bounce_state;

/* The desc with defaults filled in: zero, negative or non-finite height, radius, gravity,
 * contact_time, squash and stretch_per_speed take their defaults (squash is then clamped to
 * [0.05, 1]); a non-finite forward_speed or start becomes zero. NULL gives every default. */
AK_API ak_bounce_desc ak_bounce_desc_resolved(const ak_bounce_desc* desc);

/* The ball at time t (seconds; periodic, negative t wraps too). The bottom of the deformed
 * ball touches the floor exactly during contact and is above it in flight. Pure function;
 * NULL desc uses every default; non-finite t gives the state at t = 0. */
AK_API ak_bounce_state ak_bounce_sample(const ak_bounce_desc* desc, float t);
/* Period of one bounce (flight + contact) in seconds. */
AK_API float ak_bounce_period(const ak_bounce_desc* desc);

/* ---- follow-through: jiggle joints --------------------------------------------------------- */

typedef struct ak_jiggle_params {
    float stiffness;        /* spring, 1/s^2 (omega^2: 100 -> ~1.6 Hz); 0 = no spring (pendulum) */
    float damping;          /* 1/s (damping ratio = damping / (2 sqrt(stiffness))); 0 = none.
                               Chained joints share one frequency, so each drives its child at
                               resonance: light damping rings long down a tail; a ratio of
                               0.4 or more is a good start for chains */
    ak_vec3 gravity;        /* model-space acceleration (m/s^2); zero -> none */
    float substep;          /* integration step (s); 0 -> 1/240; shortened so that
                               substep * sqrt(stiffness) <= 0.25 and substep * damping <= 0.25 */
    uint32_t max_substeps;  /* per run, bounds the work after a long hitch; 0 -> 64 (time
                               beyond it is dropped) */
} ak_jiggle_params;

/* The parameters with defaults filled in: substep 0 -> 1/240 s, then shortened for stability
 * (substep * sqrt(stiffness) <= 0.25, substep * damping <= 0.25); max_substeps 0 -> 64.
 * The other fields are copied unchanged (the job checks them). */
AK_API ak_jiggle_params ak_jiggle_params_resolved(ak_jiggle_params params);

/* One jiggling joint. */
typedef struct ak_jiggle_joint {
    int joint;              /* skeleton index */
    ak_vec3 tip;            /* joint-local point that lags (usually the child's local translation):
                               the joint rotates about its origin to aim the tip at the particle;
                               zero -> the joint's origin itself lags (translation jiggle, bellies) */
} ak_jiggle_joint;

/* Caller-owned per-joint state; zero-initialised -> the job starts at rest on its next run (a
 * run that finds any zero state restarts every joint of the job at rest and lets no time pass). */
typedef struct ak_jiggle_state {
    ak_vec3 position;        /* particle at the last substep, model space */
    ak_vec3 velocity;        /* m/s, model space */
    ak_vec3 prev_head;       /* animated (un-jiggled) joint origin at the previous run */
    ak_vec3 prev_target;     /* animated (un-jiggled) tip at the previous run */
    float time_left;         /* time not yet integrated, carried to the next run (s, < substep) */
    uint32_t initialized;    /* 0 -> restart at rest */
    /* Scratch, rewritten by every run (no meaning between runs): */
    ak_vec3 head, target;    /* animated head and tip at this run */
    ak_quat corr_rotation;   /* jiggle correction p -> R p + t at the current substep */
    ak_vec3 corr_translation;
    int32_t ancestor;        /* slot of the nearest jiggling ancestor, -1 if none */
} ak_jiggle_state;

AK_DEFINE_SPAN(jiggle_state, ak_jiggle_state)

/* Step the jiggle joints by dt and write the model matrices with the jiggle applied. */
typedef struct ak_jiggle_job {
    ak_jiggle_params params;      /* shared by every joint of the job */
    ak_i32_cspan parents;         /* required, parent per skeleton joint (parent < index, -1 root) */
    const ak_jiggle_joint* joints;/* required, joint_count entries, strictly increasing .joint */
    size_t joint_count;           /* required, > 0 */
    ak_jiggle_state_span states;  /* required, count >= joint_count, same order as joints */
    ak_mat4_cspan model;          /* required, animated model-space matrices, count == parents.count */
    float dt;                     /* seconds since the previous run, >= 0 (0 -> no step) */
    ak_mat4_span out_model;       /* required, count >= model.count; must not overlap model:
                                     jiggled joints and their descendants move, others copy */
} ak_jiggle_job;

/* AK_ERR_NULL_ARG (parents, joints, states, model or out_model empty), AK_ERR_BAD_ARG
 * (model.count != parents.count, joints not strictly increasing, a parameter negative or
 * non-finite), AK_ERR_BAD_INDEX (a joint index out of range), AK_ERR_BAD_HIERARCHY
 * (parents[i] >= i or < -1), AK_ERR_SPAN_SMALL (states or out_model short), AK_ERR_BAD_DATA
 * (dt negative or non-finite, a non-finite model matrix). Zero-initialised -> AK_ERR_NULL_ARG. */
AK_API ak_result ak_jiggle_validate(const ak_jiggle_job* job);
/* Validate, then step: each particle follows a = stiffness (target - x) - damping v + gravity
 * (semi-implicit Euler with a fixed substep; leftover time carries to the next run). All joints
 * of the job advance together substep by substep, parents first: a joint's animated head and
 * target are interpolated linearly across the frame and carried by its nearest jiggling
 * ancestor's correction at the same substep. Rotating joints keep their length (the particle
 * stays on the sphere of radius |tip| about the head) and turn about their origin to aim the tip
 * at the particle; translating joints move by the particle's offset. The output extrapolates
 * the particle by time_left so the pose matches the frame time. Writes nothing (states
 * included) on failure. */
AK_API ak_result ak_jiggle_run(const ak_jiggle_job* job);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_DEFORM_H */
