/* animkit skeleton: joint hierarchies, joint types and limits, forward kinematics.
 *
 * What it does: an immutable skeleton (names, parents, rest pose, inverse bind matrices,
 * joint types and limits) built from a desc and validated once; forward kinematics from
 * local transforms to model-space matrices in one forward pass; skinning matrices
 * M_j = model_j * inverse_bind_j; clamping a pose to the joint limits.
 *
 * What it does NOT do: animation (clip.h), skinning (skin.h), IK (ik.h), file import (io.h).
 *
 * Joints are stored parents before children: parent[i] < i, roots have parent -1. A "bone"
 * is the segment from a joint to one of its children. A pose is an array of local
 * ak_transform, one per joint, in the parent joint's space.
 *
 * Usage:
 *     ak_joint_desc joints[3] = {
 *         { .name = "hip",   .parent = -1, .rest = ak_transform_identity() },
 *         { .name = "knee",  .parent = 0,  .rest = {{0, -0.5f, 0}, {0, 0, 0, 1}, {1, 1, 1}},
 *           .type = AK_JOINT_HINGE, .limits = { .axis = {1, 0, 0}, .min = 0, .max = 2.5f } },
 *         { .name = "ankle", .parent = 1,  .rest = {{0, -0.5f, 0}, {0, 0, 0, 1}, {1, 1, 1}} },
 *     };
 *     ak_skeleton* sk = NULL;
 *     ak_skeleton_desc d = { .joints = joints, .joint_count = 3 };
 *     if (ak_skeleton_create(&d, NULL, &sk, NULL) != AK_OK) return 1;
 *     ak_mat4 model[3];
 *     ak_skeleton_local_to_model(sk, ak_skeleton_rest_pose(sk), (ak_mat4_span)AK_SPAN(model));
 *     ak_skeleton_destroy(sk);
 *
 * Ownership and threading: a skeleton is one allocation, read-only after create, and may be
 * shared between threads. FK functions write only their output spans.
 */
#ifndef ANIMKIT_SKELETON_H
#define ANIMKIT_SKELETON_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Degrees of freedom of a joint relative to its parent. */
typedef enum ak_joint_type {
    AK_JOINT_FREE = 0, /* default: 6 DOF (3 rotation + 3 translation), no limits */
    AK_JOINT_BALL,     /* 3 rotational DOF; cone limit on the twist axis + twist range */
    AK_JOINT_HINGE,    /* "pin": 1 rotation about limits.axis within [min, max] radians */
    AK_JOINT_PRISM,    /* "slider": 1 translation along limits.axis within [min, max] */
    AK_JOINT_TYPE_COUNT
} ak_joint_type;

/* Limits, all relative to the joint's rest (bind) local transform. Rotations are measured
 * as rel = rest.rotation^-1 * local.rotation, i.e. in the joint's own rest frame, where the
 * axis is given; a prism slides along rest.rotation * axis in the parent's space. */
typedef struct ak_joint_limits {
    ak_vec3 axis;      /* joint space: hinge rotation axis, prism slide axis, ball twist axis
                          (usually towards the child); zero -> (1,0,0) hinge/prism, (0,1,0) ball */
    float min, max;    /* hinge: radians; prism: length units; both 0 -> unlimited */
    float cone_angle;  /* ball: max swing of the twist axis from rest, radians; 0 -> unlimited */
    float twist_min, twist_max; /* ball: twist about axis, radians; both 0 -> unlimited */
} ak_joint_limits;

typedef struct ak_joint_desc {
    const char* name;       /* required, unique; copied (truncated to AK_NAME_SIZE-1) */
    int parent;             /* index of the parent, -1 for a root; must be < this index */
    ak_transform rest;      /* local bind/rest transform; zero-init is invalid (zero rotation
                               and scale): use ak_transform_identity() or set all three */
    const ak_mat4* inverse_bind; /* model-space inverse bind matrix; NULL -> inverse of the
                                    rest pose's model matrix */
    ak_joint_type type;     /* 0 -> AK_JOINT_FREE */
    ak_joint_limits limits; /* used by the type; zero -> unlimited */
} ak_joint_desc;

/* The most joints a skeleton holds (parent indices are int32; 2^20 = 1,048,576). */
#define AK_SKELETON_MAX_JOINTS 1048576u

typedef struct ak_skeleton_desc {
    const ak_joint_desc* joints; /* required, parents before children */
    size_t joint_count;          /* required, 1 .. AK_SKELETON_MAX_JOINTS */
    const char* name;            /* NULL -> "" */
    bool palette_from_skins;     /* true: meshes bound to this skeleton index the slots of
                                    their own skins, not skeleton joints (every scene loaded
                                    from a file, see scene.h), so a palette indexed by joint
                                    would skin them wrong: ak_skeleton_skinning_matrices then
                                    refuses (AK_ERR_UNSUPPORTED) and ak_scene_skin_palette
                                    is the way. false: a mesh's joint indices are skeleton
                                    joint indices (builtin scenes, hand-made skeletons) */
} ak_skeleton_desc;

typedef struct ak_skeleton ak_skeleton;

/* Build a skeleton. Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (no joints), AK_ERR_BAD_ARG (too many
 * joints, unknown type, an allocator with only one of alloc/free set), AK_ERR_BAD_HIERARCHY (parent >= own index or < -1: use
 * ak_skeleton_reorder first), AK_ERR_DUPLICATE (two joints share a name), AK_ERR_NULL_ARG
 * (a joint has no name), AK_ERR_BAD_DATA (NaN/inf in a rest transform, inverse bind or
 * limits; a zero-length rest rotation; min > max), AK_ERR_NO_MEMORY. diag (optional) names the
 * joint. On failure *out_skeleton is NULL. */
AK_API ak_result ak_skeleton_create(const ak_skeleton_desc* desc, const ak_allocator* alloc,
                                    ak_skeleton** out_skeleton, ak_diag* diag);
/* NULL is a no-op. */
AK_API void ak_skeleton_destroy(ak_skeleton* skeleton);

/* Sort joints given in any order so that parents come before children (stable: joints keep
 * their relative order where the hierarchy allows). parents[i] is the parent of joint i (-1 for
 * roots), in the input numbering. out_order[k] = input index of the joint placed at k.
 * Returns AK_ERR_BAD_HIERARCHY on a cycle or a parent index out of range,
 * AK_ERR_SPAN_SMALL when out_order.count < parents.count, AK_ERR_NULL_ARG, AK_ERR_NO_MEMORY
 * (an offline helper: it keeps one byte per joint of scratch on the C heap). A joint moves
 * earlier only when a joint listed before it needs it as an ancestor. */
AK_API ak_result ak_skeleton_reorder(ak_i32_cspan parents, ak_i32_span out_order);

/* Number of joints (0 for NULL). */
AK_API size_t ak_skeleton_joint_count(const ak_skeleton* skeleton);
/* Parent index per joint (parent[i] < i, -1 for roots); empty span for NULL. */
AK_API ak_i32_cspan ak_skeleton_parents(const ak_skeleton* skeleton);
/* Rest (bind) local transform per joint; empty span for NULL. */
AK_API ak_transform_cspan ak_skeleton_rest_pose(const ak_skeleton* skeleton);
/* Model-space inverse bind matrix per joint; empty span for NULL. */
AK_API ak_mat4_cspan ak_skeleton_inverse_binds(const ak_skeleton* skeleton);
/* Name of joint index; "" when out of range. */
AK_API const char* ak_skeleton_joint_name(const ak_skeleton* skeleton, size_t joint_index);
/* Index of the joint with this exact name, or -1. */
AK_API int ak_skeleton_find_joint(const ak_skeleton* skeleton, const char* name);
/* Type of a joint (AK_JOINT_FREE when out of range). */
AK_API ak_joint_type ak_skeleton_joint_type(const ak_skeleton* skeleton, size_t joint_index);
/* Limits with defaults resolved (axis normalised, never zero). */
AK_API ak_joint_limits ak_skeleton_joint_limits(const ak_skeleton* skeleton, size_t joint_index);
/* desc.palette_from_skins as created (false for NULL). */
AK_API bool ak_skeleton_palette_from_skins(const ak_skeleton* skeleton);
/* Number of children of a joint (0: a leaf, or out of range). */
AK_API size_t ak_skeleton_child_count(const ak_skeleton* skeleton, size_t joint_index);

/* FK kernels, for ak_skeleton_set_simd_limit. */
typedef enum ak_fk_simd {
    AK_FK_SIMD_DEFAULT = 0, /* the widest kernel this CPU has */
    AK_FK_SIMD_SCALAR,      /* portable code (SSE2 columns on x86-64): ak_mat4_mul's floats */
    AK_FK_SIMD_AVX2,        /* at most AVX2 + FMA (AVX without FMA on CPUs that lack them) */
    AK_FK_SIMD_AVX512,      /* at most AVX-512 F + VL (FMA; sums in another order than AVX2) */
    AK_FK_SIMD_COUNT
} ak_fk_simd;

/* Cap the FK kernel this skeleton's FK functions use (the widest the CPU has, checked at run
 * time, at or below limit; create picks the DEFAULT). For comparisons and tests: call it before
 * sharing the skeleton between threads. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (out of
 * range). */
AK_API ak_result ak_skeleton_set_simd_limit(ak_skeleton* skeleton, ak_fk_simd limit);
/* The FK kernel in use: "scalar", "avx" (AVX, no FMA), "avx2" (AVX2 + FMA) or "avx512"
 * ("" for NULL). */
AK_API const char* ak_skeleton_simd_name(const ak_skeleton* skeleton);

/* Forward kinematics: local[i] -> model[i] = model[parent] * local[i] (model[root] = local).
 * Needs local.count >= joint_count, out_model.count >= joint_count. Returns AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL. Non-finite input propagates (validate poses with ak_pose_is_finite).
 * Local matrices are built eight joints at a time (structure of arrays) and multiplied as
 * affine matrices; the kernels with FMA (AVX2 + FMA, AVX-512, chosen at run time, see
 * ak_skeleton_set_simd_limit) use fused multiply-adds, so the floats may differ from
 * ak_mat4_mul chains by a rounding per product (the scalar and AVX kernels give the same
 * floats). */
AK_API ak_result ak_skeleton_local_to_model(const ak_skeleton* skeleton, ak_transform_cspan local,
                                            ak_mat4_span out_model);
/* Same, with an extra root transform (e.g. the node above the skeleton) applied to every root. */
AK_API ak_result ak_skeleton_local_to_model_rooted(const ak_skeleton* skeleton, ak_mat4 root,
                                                   ak_transform_cspan local, ak_mat4_span out_model);
/* Skinning palette indexed by skeleton joint: out_skin[i] = model[i] * inverse_bind[i]. Sizes
 * >= joint_count. Right for meshes whose joint indices are skeleton joints (builtin scenes,
 * your own skeletons). A scene loaded from a file indexes each mesh's joints by the slots of
 * its skin, whose order and inverse binds are the skin's own: build its palette with
 * ak_scene_skin_palette. Such a skeleton (desc.palette_from_skins, set by the loaders) makes
 * this function return AK_ERR_UNSUPPORTED, writing nothing, instead of a palette that would
 * silently skin the mesh wrong. Also AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skeleton_skinning_matrices(const ak_skeleton* skeleton, ak_mat4_cspan model,
                                               ak_mat4_span out_skin);
/* FK for many characters sharing one skeleton: poses are character-major,
 * local.count >= character_count * joint_count, same for out_model. */
AK_API ak_result ak_skeleton_local_to_model_batch(const ak_skeleton* skeleton, size_t character_count,
                                                  ak_transform_cspan local, ak_mat4_span out_model);

/* Clamp a pose (local transforms, in place) to the joint types and limits: hinge joints keep
 * only the rotation about their axis relative to rest, clamped to [min, max] (an angle outside
 * goes to the nearer end on the circle); ball joints get their swing clamped to the cone and
 * their twist to [twist_min, twist_max]; prism joints keep the rest rotation and slide along
 * their axis within [min, max]; free joints are unchanged. Hinge, ball and prism joints have
 * no free translation: hinge and ball get the rest translation back. Scale is left as given.
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skeleton_apply_limits(const ak_skeleton* skeleton, ak_transform_span pose);
/* Clamp one joint's local transform (the routine ak_skeleton_apply_limits uses per joint). */
AK_API ak_transform ak_skeleton_limit_joint(const ak_skeleton* skeleton, size_t joint_index, ak_transform local);
/* True when the local transform satisfies its joint's limits within tol (radians / units):
 * the same rules as the clamp (a hinge also needs its off-axis swing <= tol and translation
 * within tol of rest). Free joints: always true. Out-of-range index or non-finite input: false. */
AK_API bool ak_skeleton_joint_within_limits(const ak_skeleton* skeleton, size_t joint_index, ak_transform local,
                                            float tol);

/* Decompose rotation q into swing * twist about axis (normalised here): twist is a rotation
 * about axis, swing one about an axis perpendicular to it (q = swing * twist, both unit).
 * When q turns axis by exactly 180 degrees the twist is undefined: twist = identity. */
AK_API void ak_quat_swing_twist(ak_quat q, ak_vec3 axis, ak_quat* out_swing, ak_quat* out_twist);

/* True when every transform in the span is finite. */
AK_API bool ak_pose_is_finite(ak_transform_cspan pose);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_SKELETON_H */
