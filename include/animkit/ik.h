/* animkit ik: inverse kinematics on joint chains and trees of a skeleton pose.
 *
 * What it does: finds local joint rotations (and prism-joint slides) that put an end effector
 * at a target. Solvers: CCD (cyclic coordinate descent, tip to root), FABRIK (Aristidou &
 * Lasenby 2011, forward and backward reaching, converted back to rotations keeping each
 * joint's twist), an analytic two-bone solver (law of cosines, pole vector, soft reach limit,
 * blend weight), and damped least squares (Jacobian, Levenberg-Marquardt adaptive damping
 * with Buss & Kim's step and target clamps, position and optional orientation targets). FABRIK also solves trees with several end
 * effectors (sub-bases, as in the paper). The two-bone solver also comes as a batch
 * (ak_ik_two_bone_run_many: many limbs per call, four at a time in SIMD registers). Every
 * chain solver honours the skeleton's joint types and limits (each changed rotation or slide
 * is clamped as ak_skeleton_limit_joint does; a rotating joint's translation is left as the
 * pose has it) and reports whether the target was reached, the remaining distance and the
 * iterations used.
 *
 * What it does NOT do: forward kinematics for the caller (skeleton.h), animation blending,
 * collision avoidance, or move the chain root: the root joint's position is fixed, it only
 * rotates. Non-uniform scale on chain joints is approximated (see ak_transform_mul).
 *
 * Spaces: a pose is the skeleton's array of local transforms; targets and positions are in
 * model space (the skeleton's space, ak_skeleton_local_to_model; for a scene this is world
 * space). A chain is a list of joint indices from a root to the end effector, each the parent
 * of the next (ak_ik_chain_build); ak_ik_chain_positions gives its joint positions before
 * and after a solve.
 *
 * Usage:
 *     int16_t chain[8]; size_t chain_count = 0;
 *     ak_ik_chain_build(sk, hip, ankle, (ak_i16_span)AK_SPAN(chain), &chain_count);
 *     unsigned char scratch[4096];                 // >= ak_ik_chain_scratch_size(solver, n)
 *     bool reached; float error; size_t iterations;
 *     ak_ik_chain_job job = {
 *         .skeleton = sk, .pose = pose,            // ak_transform_span, edited in place
 *         .chain = {chain, chain_count},
 *         .target = ak_vec3_make(0.2f, 0.1f, 0.3f), // model space
 *         .solver = AK_IK_SOLVER_FABRIK,
 *         .scratch = (ak_u8_span)AK_SPAN(scratch),
 *         .out_reached = &reached, .out_error = &error, .out_iterations = &iterations,
 *     };
 *     ak_result r = ak_ik_chain_run(&job);          // AK_OK even when !reached
 *
 * Ownership and threading: jobs keep no pointer after run returns and never allocate; the
 * caller passes scratch memory (any alignment). Jobs writing different poses may run in
 * parallel on one skeleton.
 */
#ifndef ANIMKIT_IK_H
#define ANIMKIT_IK_H

#include "skeleton.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- chains ------------------------------------------------------------------------- */

/* The joints from root_joint down to effector_joint (inclusive), root first, each the parent
 * of the next: out_joints[0] = root_joint, out_joints[*out_count - 1] = effector_joint.
 * root_joint == effector_joint gives a one-joint chain. Needs out_joints.count >= the chain's
 * joint count (ak_skeleton_joint_count always suffices). Returns AK_ERR_NULL_ARG,
 * AK_ERR_BAD_INDEX (a joint out of range), AK_ERR_NOT_FOUND (root_joint is not an ancestor
 * of effector_joint), AK_ERR_SPAN_SMALL (*out_count then holds the size needed),
 * AK_ERR_UNSUPPORTED (effector_joint above 32767: chains hold int16 joint indices). */
AK_API ak_result ak_ik_chain_build(const ak_skeleton* skeleton, int root_joint, int effector_joint,
                                   ak_i16_span out_joints, size_t* out_count);

/* Model-space positions of the chain's joints for a pose (the forward kinematics of the
 * chain's ancestors and the chain only). Needs pose.count >= joint count,
 * out_positions.count >= chain.count. Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL,
 * AK_ERR_BAD_INDEX, AK_ERR_BAD_HIERARCHY (chain not parent-linked). */
AK_API ak_result ak_ik_chain_positions(const ak_skeleton* skeleton, ak_transform_cspan pose,
                                       ak_i16_cspan chain, ak_vec3_span out_positions);

/* Sum of the chain's bone lengths in model space for a pose (0 on invalid input), summed in
 * double and saturated at FLT_MAX (never infinite). */
AK_API float ak_ik_chain_length(const ak_skeleton* skeleton, ak_transform_cspan pose, ak_i16_cspan chain);

/* ---- the chain job ------------------------------------------------------------------ */

typedef enum ak_ik_solver {
    AK_IK_SOLVER_DEFAULT = 0, /* -> AK_IK_SOLVER_FABRIK */
    AK_IK_SOLVER_CCD,         /* cyclic coordinate descent */
    AK_IK_SOLVER_FABRIK,      /* forward and backward reaching */
    AK_IK_SOLVER_TWO_BONE,    /* analytic; the chain must have exactly 3 joints */
    AK_IK_SOLVER_DLS,         /* damped least squares Jacobian, adaptive damping (see
                                 ak_ik_chain_run) */
    AK_IK_SOLVER_COUNT
} ak_ik_solver;

/* "ccd", "fabrik", "twobone", "dls" ("default" for AK_IK_SOLVER_DEFAULT); "" when unknown. */
AK_API const char* ak_ik_solver_name(ak_ik_solver solver);
/* Solver from its name (as ak_ik_solver_name writes it; "two_bone" and "two-bone" too).
 * Returns AK_ERR_NULL_ARG, AK_ERR_NOT_FOUND (unknown name). */
AK_API ak_result ak_ik_solver_parse(const char* name, ak_ik_solver* out_solver);

/* Solve one chain in place. Inputs first, then options (all zero by default), then outputs. */
typedef struct ak_ik_chain_job {
    const ak_skeleton* skeleton; /* required */
    ak_transform_span pose;      /* required, in/out: local transforms, count >= joint count;
                                    only the chain's joints are written */
    ak_i16_cspan chain;          /* required: joint indices root..effector, each the parent of
                                    the next (ak_ik_chain_build), count >= 1 */
    ak_vec3 target;              /* model space position for the effector (last chain joint) */
    const ak_quat* target_rotation; /* model space rotation for the effector; NULL -> position
                                       only. DLS solves for it with the whole chain; the other
                                       solvers set the effector joint's own rotation after
                                       placing it (then clamp it to its limits) */
    ak_ik_solver solver;         /* 0 -> FABRIK */
    size_t max_iterations;       /* iteration budget; 0 -> 50. CCD: one sweep over the chain;
                                    FABRIK: one forward + backward pass; DLS: one step */
    float tolerance;             /* model units: reached when the effector is this close;
                                    0 -> 1e-4 * chain length (1e-7 for a chain of zero
                                    length) */
    float angle_tolerance;       /* radians, with target_rotation; 0 -> 1e-3 */
    float max_step;              /* CCD: largest rotation of one joint in one sweep, radians
                                    (damping); 0 -> pi (undamped) */
    bool ccd_from_root;          /* CCD: visit the joints root to tip; false -> tip to root,
                                    the classic order */
    bool ignore_limits;          /* false -> joint types and limits are honoured */
    float dls_damping;           /* DLS: initial lambda, model units (adapted each step,
                                    within [1e-6, 1e4] x chain length; see ak_ik_chain_run);
                                    0 -> 0.1 * chain length (1e-6 at zero length) */
    float orientation_weight;    /* DLS: model units per radian of orientation error;
                                    0 -> chain length / pi (1e-6 at zero length) */
    ak_vec3 pole;                /* TWO_BONE: model-space direction the middle joint bends
                                    towards (a knee points along it); zero -> keep the
                                    current bend plane */
    float soft;                  /* TWO_BONE: softening band, a fraction in [0, 1) of the
                                    reach: targets beyond (1 - soft) * reach are approached
                                    smoothly so the limb never snaps straight; 0 -> hard */
    float keep_animation;        /* TWO_BONE: blend back towards the input pose, [0, 1]:
                                    0 -> full IK, 1 -> pose unchanged */
    ak_u8_span scratch;          /* >= ak_ik_chain_scratch_size(solver, chain.count) bytes,
                                    any alignment */
    bool* out_reached;           /* optional: effector within tolerance (and angle tolerance) */
    float* out_error;            /* optional: final effector-to-target distance, model units
                                    (computed in double; saturates at FLT_MAX, never inf) */
    float* out_angle_error;      /* optional: final orientation error in radians (0 without
                                    target_rotation) */
    size_t* out_iterations;      /* optional: iterations used (0 for TWO_BONE) */
} ak_ik_chain_job;

/* Bytes of scratch a chain job needs for this solver and chain length (never 0). */
AK_API size_t ak_ik_chain_scratch_size(ak_ik_solver solver, size_t chain_count);

/* The job with zero options replaced by their defaults (solver, max_iterations, tolerance
 * from the chain length in the pose, angle_tolerance, max_step, dls_damping,
 * orientation_weight). Fields that cannot be resolved (no skeleton or pose) stay zero. */
AK_API ak_ik_chain_job ak_ik_chain_job_resolved(const ak_ik_chain_job* job);

/* Check a chain job; returns the first rule that fails:
 *   AK_ERR_NULL_ARG    job, skeleton, pose.ptr or chain.ptr is NULL, or chain.count is 0
 *   AK_ERR_SPAN_SMALL  pose.count < joint count
 *   AK_ERR_BAD_ARG     solver out of range
 *   AK_ERR_BAD_INDEX   a chain joint index is out of range
 *   AK_ERR_BAD_HIERARCHY  chain[k-1] is not the parent of chain[k]
 *   AK_ERR_BAD_ARG     TWO_BONE with chain.count != 3
 *   AK_ERR_BAD_DATA    target, *target_rotation (or a zero quaternion) or pole not finite
 *   AK_ERR_BAD_ARG     tolerance, angle_tolerance, max_step, dls_damping or
 *                      orientation_weight negative or NaN; soft outside [0, 1);
 *                      keep_animation outside [0, 1]
 *   AK_ERR_BAD_DATA    a transform of the chain or its ancestors in the pose is not finite,
 *                      or the chain's model-space transforms overflow (finite locals whose
 *                      forward kinematics is not finite, e.g. bones of 3e38 end to end)
 *   AK_ERR_NULL_ARG    scratch.ptr is NULL
 *   AK_ERR_SPAN_SMALL  scratch.count < ak_ik_chain_scratch_size(solver, chain.count) */
AK_API ak_result ak_ik_chain_validate(const ak_ik_chain_job* job);

/* Validate, then solve, writing the chain joints' local rotations (prism joints: local
 * translations) into pose. Returns validate's codes; nothing is written when it fails.
 * Outcome: AK_OK whether or not the target was reached. Unreachable targets leave the chain
 * straightened towards the target, *out_reached false and *out_error the remaining distance.
 * Iterations stop early when the error has not improved for 3 iterations (no oscillation
 * until the budget runs out), and the iterative solvers return the best pose they met, so
 * never one farther from the target than the input pose.
 * Joint types: FREE and BALL joints rotate freely (BALL within cone and twist), HINGE joints
 * about their axis, PRISM joints keep their rotation and slide (CCD and DLS move slides;
 * FABRIK and TWO_BONE keep them). Only rotations and slides are written, so bone lengths
 * (other than prism slides) are unchanged.
 * Solver notes: CCD is the course's algorithm as is; its tail is slow (one joint at a time).
 * A straight chain whose line passes through the target (inside its reach) is singular for
 * CCD, FABRIK and DLS alike, so such a chain is first curled in one plane: the plane of the
 * first hinge below the root (bent to the side its limits allow), else of the root's hinge,
 * else ak_vec3_any_perpendicular of the line; every joint below the root turns by one angle
 * (bisected so the curled chord equals the target's distance, within the hinges' limits)
 * and the root turns the effector back onto the line. The wider curl takes any straight or
 * nearly straight chain (every joint within 1e-3 x chain length of the root-effector line)
 * whose target is nearer the root than the chain's length, on the line or off it (the root
 * then turns the effector towards the target): near the line, first-order steps gain less
 * than float positions resolve, so a target 1e-5 off the line stalled as one on it did.
 * DLS curls so before iterating; CCD and constrained FABRIK curl so, twice at most, when
 * they stall (a hinge clamped straight, or the chain turned to point at a target near its
 * line), and so does DLS. The curl depends on the target only through its distance and
 * direction, so nearby targets give nearby poses, and the same job gives the same bits.
 * DLS step (Wampler 1986; Buss 2004; Buss & Kim 2005), J the 3 x dof (6 x dof with
 * target_rotation, orientation rows times orientation_weight) Jacobian of the effector:
 *     dq = ClampMaxAbs(J^T (J J^T + lambda^2 I)^-1 e', pi / 4),
 *     e' = e min(1, (L / 2) / |position error|)    (a far target pulls by its direction)
 * L the chain length; ClampMaxAbs scales dq so no joint turns more than pi / 4 (a slide of
 * L counts as 1 rad). In singular values the step is sum_i s_i / (s_i^2 + lambda^2)
 * (u_i . e') v_i: lambda damps the directions a nearly singular J resolves badly. lambda
 * starts at dls_damping and adapts to the error (Levenberg-Marquardt): a step that lowers
 * it is kept and lambda halves (down to 1e-6 L), one that does not is undone and lambda
 * grows 4x (up to 1e4 L); each try counts as an iteration. A limited hinge at its limit
 * whose step points further out leaves J for that step.
 * FABRIK on a chain with limits first runs the plain passes (their answer often respects the
 * limits, e.g. a planar chain of hinges); if the converted pose misses, the remaining
 * iterations run constrained, from the better of the converted pose and the input: the
 * backward pass turns each joint within its limits, followed by one constrained CCD sweep
 * (from the best pose met when the limits made the pass's pose worse) so joints pinned at a
 * limit do not freeze the chain.
 * While plain FABRIK passes shrink the error by less than half per pass (slow convergence
 * near full reach), each next pass starts from the positions extrapolated by the last pass's
 * step (a momentum step; the passes themselves keep the bone lengths).
 * TWO_BONE bends a HINGE mid joint about the hinge axis (trying the other bend when the limits
 * refuse the first). DLS stops when lambda tops out without an improving step.
 * Scale: chains of any size work alike. A chain 1e-3 to 1e6 units long with its target
 * within 1e9 of its root is solved as it is; any other runs in a frame centred on the chain
 * root and scaled by a power of two that brings the chain's extent into [0.5, 1) (exact), so
 * bones of 1e30 do not overflow squared distances and bones of 1e-30 do not fall under fixed
 * thresholds; there a target farther than 1e6 chain extents from the root is solved as the
 * point on its ray from the root at that distance (out of reach either way). Error and
 * reached always use the true target, in double.
 * Degenerate cases: a one-joint chain cannot move its effector (only target_rotation is
 * applied; 0 iterations); zero-length bones keep their direction; a target on the root folds
 * the chain as far as lengths and limits allow. */
AK_API ak_result ak_ik_chain_run(const ak_ik_chain_job* job);

/* ---- analytic two-bone (model space, no skeleton) ------------------------------------ */

/* The fast analytic solver on three model-space joint matrices (as ak_skeleton_local_to_model
 * gives), after ozz's IKTwoBoneJob: outputs rotation corrections to multiply onto the start
 * and mid joints' local rotations: local.rotation = ak_quat_mul(local.rotation, *out_x_rot).
 * Matrices must be rigid with uniform positive scale. Does not know about joint limits.
 * Bend side: by default the limb keeps the side it is bent to in the input (the sign of
 * mid_axis does not matter; the mid correction is the smaller of the two that reach; a
 * straight input bends with (mid - start) x (end - mid) along +mid_axis), so an input that
 * passes through straight or hyperextends (animation noise) flips the bend. ozz's
 * IKTwoBoneJob instead reads the sign of mid_axis: a positive rotation about it opens the
 * joint, so the limb always ends bent with (mid - start) x (end - mid) along -mid_axis, and a
 * limb bent the other way in the input (e.g. a hyperextended knee) flips through straight.
 * mid_axis_signed = true selects ozz's convention (use it for a knee or an elbow, which bends
 * one way only). The two give the same joint positions
 * (the pole puts the mid joint on its side either way) but, for a limb bent against
 * mid_axis, start, mid and end orientations that differ by half a turn about each bone: a
 * hand or foot below the end joint turns over. */
typedef struct ak_ik_two_bone_job {
    ak_mat4 start, mid, end; /* model space joint matrices (e.g. hip, knee, ankle) */
    ak_vec3 target;          /* model space */
    ak_vec3 pole;            /* model-space direction the mid joint bends towards; zero -> keep
                                the current bend plane */
    ak_vec3 mid_axis;        /* mid joint's local bend axis (a knee hinge); zero -> the normal
                                of the current bend plane (any perpendicular when straight) */
    bool mid_axis_signed;    /* with a nonzero mid_axis: true -> its sign sets the bend side
                                (ozz's convention: a positive rotation about mid_axis opens the
                                joint); false -> keep the input's bend side. No effect without
                                mid_axis */
    float twist;             /* radians: extra rotation of the bend plane about the
                                start-to-target axis; 0 -> none */
    float soft;              /* softening band in [0, 1) of the reach; 0 -> hard limit */
    float keep_animation;    /* [0, 1]: 0 -> full correction, 1 -> identity corrections */
    ak_quat* out_start_rot;  /* required: local correction of the start joint */
    ak_quat* out_mid_rot;    /* required: local correction of the mid joint */
    bool* out_reached;       /* optional: target within reach (not clamped nor softened) */
} ak_ik_two_bone_job;

/* AK_ERR_NULL_ARG (job, out_start_rot or out_mid_rot NULL), AK_ERR_BAD_DATA (a matrix,
 * target, pole or mid_axis not finite), AK_ERR_BAD_ARG (soft outside [0, 1), keep_animation
 * outside [0, 1]). */
AK_API ak_result ak_ik_two_bone_validate(const ak_ik_two_bone_job* job);
/* Validate, then solve; writes nothing when validation fails. Degenerate cases: a target
 * outside [|a - b|, a + b] (a, b the bone lengths) straightens or folds the limb towards it
 * and reports not reached; a target on the start joint or zero-length bones give identity
 * corrections for the undefined part. */
AK_API ak_result ak_ik_two_bone_run(const ak_ik_two_bone_job* job);
/* ak_ik_two_bone_run on each of jobs[0..count) (e.g. both legs of every character of a crowd),
 * with exactly its results, four jobs at a time in SIMD registers where the common case
 * applies (a pole, no mid_axis, soft, keep_animation or twist, a limb bent by more than ~3
 * degrees); the other jobs run ak_ik_two_bone_run one by one. Each job is validated on its
 * own: a job that fails gets nothing written and the others are still solved. Returns AK_OK,
 * or the first failing job's code with its index in *out_failed (optional; count when none
 * failed); AK_ERR_NULL_ARG when jobs is NULL and count > 0. */
AK_API ak_result ak_ik_two_bone_run_many(const ak_ik_two_bone_job* jobs, size_t count, size_t* out_failed);

/* ---- FABRIK on a tree with several end effectors ------------------------------------- */

/* FABRIK with sub-bases (Aristidou & Lasenby 2011, section 4.3): the tree is the union of the
 * paths from root_joint to each effector. Forward reaching runs from every effector towards
 * the root, placing each sub-base at the centroid of its branches' proposals; backward
 * reaching runs from the fixed root outwards. Each iteration converts the positions back to
 * rotations (joints with several tree children get the best-fit rotation of their bones, the
 * first 64 children only) and applies limits. */
typedef struct ak_ik_fabrik_tree_job {
    const ak_skeleton* skeleton; /* required */
    ak_transform_span pose;      /* required, in/out: local transforms, count >= joint count */
    int root_joint;              /* fixed base joint; an ancestor of every effector (or one) */
    ak_i16_cspan effectors;      /* required: effector joint indices, count >= 1, distinct */
    ak_vec3_cspan targets;       /* required: model space, count >= effectors.count */
    size_t max_iterations;       /* 0 -> 50 */
    float tolerance;             /* model units, per effector; 0 -> 1e-4 * tree bone length
                                    (1e-7 at zero length) */
    bool ignore_limits;          /* false -> limits honoured */
    ak_u8_span scratch;          /* >= ak_ik_fabrik_tree_scratch_size(joint count) bytes */
    bool* out_reached;           /* optional: every effector within tolerance */
    float* out_error;            /* optional: largest effector-to-target distance (double,
                                    saturates at FLT_MAX) */
    size_t* out_iterations;      /* optional */
} ak_ik_fabrik_tree_job;

/* Bytes of scratch for a skeleton of joint_count joints (never 0). */
AK_API size_t ak_ik_fabrik_tree_scratch_size(size_t joint_count);
/* AK_ERR_NULL_ARG (job, skeleton, pose.ptr, effectors.ptr, targets.ptr NULL or
 * effectors.count 0), AK_ERR_SPAN_SMALL (pose or targets too short), AK_ERR_BAD_INDEX
 * (root or an effector out of range), AK_ERR_DUPLICATE (an effector listed twice),
 * AK_ERR_NOT_FOUND (root_joint not an ancestor of an effector), AK_ERR_BAD_DATA (a target or
 * a pose transform not finite, or an effector's model transform overflows), AK_ERR_BAD_ARG (tolerance negative or NaN),
 * AK_ERR_NULL_ARG / AK_ERR_SPAN_SMALL (scratch). */
AK_API ak_result ak_ik_fabrik_tree_validate(const ak_ik_fabrik_tree_job* job);
/* Validate, then solve in place; unreachable targets, scale and far targets as for chains. */
AK_API ak_result ak_ik_fabrik_tree_run(const ak_ik_fabrik_tree_job* job);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_IK_H */
