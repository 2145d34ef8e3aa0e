/* Shared between the IK source files: the chain working state and small math helpers. */
#ifndef ANIMKIT_IK_INTERNAL_H
#define ANIMKIT_IK_INTERNAL_H

#include <animkit/ik.h>

#include "internal.h"
#include "simd.h"

/* Working state of one chain solve. world[i] is the model transform of chain joint i;
 * base is the model transform of the chain root's parent (identity for a skeleton root). */
typedef struct akp_ik_chain {
    const ak_skeleton* skeleton;
    ak_transform* pose;    /* the caller's pose (all joints) */
    const int16_t* joints; /* chain joint indices, root first */
    size_t count;
    ak_transform base;
    ak_transform* world; /* [count] scratch */
    ak_transform* best;  /* [count] scratch: chain locals of the best pose seen */
    uint8_t* types;      /* [count] scratch: ak_joint_type per chain joint, FREE when limits are off */
    uint8_t* clamp;      /* [count] scratch: 1 when the joint has limits that can clip a rotation
                            the solvers produce (an unlimited hinge turned about its own axis,
                            or an unlimited ball, cannot be clipped) */
    float best_error;
    ak_vec3 target;
    bool limits; /* honour joint types and limits */
    float length; /* sum of bone lengths, model units */
    float tolerance;
} akp_ik_chain;

/* Solver outcome shared by the chain solvers. */
typedef struct akp_ik_outcome {
    float error;
    size_t iterations;
} akp_ik_outcome;

/* Model rotation of chain joint i's parent. */
static inline ak_quat akp_ik_parent_rot(const akp_ik_chain* c, size_t i) {
    return i == 0 ? c->base.rotation : c->world[i - 1].rotation;
}
static inline ak_transform akp_ik_parent_world(const akp_ik_chain* c, size_t i) {
    return i == 0 ? c->base : c->world[i - 1];
}

#if AK_SIMD_SSE2
/* Quaternion product a * b, (x, y, z, w) lanes:
 * a.w b + a.x (b.w, -b.z, b.y, -b.x) + a.y (b.z, b.w, -b.x, -b.y) + a.z (-b.y, b.x, b.w, -b.z). */
static inline __m128 akp_ik_qmul_sse(__m128 a, __m128 b) {
    const __m128 b1 = _mm_xor_ps(_mm_shuffle_ps(b, b, _MM_SHUFFLE(0, 1, 2, 3)), _mm_set_ps(-0.0f, 0.0f, -0.0f, 0.0f));
    const __m128 b2 = _mm_xor_ps(_mm_shuffle_ps(b, b, _MM_SHUFFLE(1, 0, 3, 2)), _mm_set_ps(-0.0f, -0.0f, 0.0f, 0.0f));
    const __m128 b3 = _mm_xor_ps(_mm_shuffle_ps(b, b, _MM_SHUFFLE(2, 3, 0, 1)), _mm_set_ps(-0.0f, 0.0f, 0.0f, -0.0f));
    __m128 r = _mm_mul_ps(AKP_SIMD_SPLAT(a, 3), b);
    r = _mm_add_ps(r, _mm_mul_ps(AKP_SIMD_SPLAT(a, 0), b1));
    r = _mm_add_ps(r, _mm_mul_ps(AKP_SIMD_SPLAT(a, 1), b2));
    return _mm_add_ps(r, _mm_mul_ps(AKP_SIMD_SPLAT(a, 2), b3));
}
/* a x b in the x, y, z lanes (w lane: 0 for finite input): (a * b.yzx - a.yzx * b).yzx. */
static inline __m128 akp_ik_cross_sse(__m128 a, __m128 b) {
    const __m128 a1 = _mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 0, 2, 1)), b1 = _mm_shuffle_ps(b, b, _MM_SHUFFLE(3, 0, 2, 1));
    const __m128 c = _mm_sub_ps(_mm_mul_ps(a, b1), _mm_mul_ps(a1, b));
    return _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 0, 2, 1));
}
#endif

/* parent * local for unit rotations: like ak_transform_mul without the renormalisation, which
 * the solvers do once per changed joint instead. */
static inline ak_transform akp_ik_compose(ak_transform parent, ak_transform local) {
    ak_transform r;
#if AK_SIMD_SSE2
    /* rotation: one SSE product; translation: v + w t + q x t, t = 2 q x v (v the scaled
     * local translation), two SSE cross products. */
    const __m128 pq = _mm_loadu_ps(&parent.rotation.x);
    _mm_storeu_ps(&r.rotation.x, akp_ik_qmul_sse(pq, _mm_loadu_ps(&local.rotation.x)));
    r.scale = ak_vec3_mul(parent.scale, local.scale);
    const ak_vec3 lv = ak_vec3_mul(parent.scale, local.translation);
    const __m128 v = _mm_set_ps(0.0f, lv.z, lv.y, lv.x);
    const __m128 qv = _mm_and_ps(pq, _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1)));
    const __m128 t = akp_ik_cross_sse(qv, _mm_add_ps(v, v));
    const __m128 o = _mm_add_ps(_mm_add_ps(v, _mm_mul_ps(AKP_SIMD_SPLAT(pq, 3), t)), akp_ik_cross_sse(qv, t));
    float f[4];
    _mm_storeu_ps(f, o);
    r.translation = ak_vec3_make(parent.translation.x + f[0], parent.translation.y + f[1], parent.translation.z + f[2]);
    return r;
#else
    r.rotation = ak_quat_mul(parent.rotation, local.rotation);
    r.scale = ak_vec3_mul(parent.scale, local.scale);
    r.translation = ak_vec3_add(parent.translation, ak_quat_rotate(parent.rotation, ak_vec3_mul(parent.scale, local.translation)));
    return r;
#endif
}

/* Recompute world[from..count-1] from the pose. */
static inline void akp_ik_fk(akp_ik_chain* c, size_t from) {
    for (size_t i = from; i < c->count; ++i)
        c->world[i] = akp_ik_compose(akp_ik_parent_world(c, i), c->pose[c->joints[i]]);
}

/* Remember the current pose when it beats the best error so far. */
static inline void akp_ik_track_best(akp_ik_chain* c, float error) {
    if (!(error < c->best_error)) return;
    c->best_error = error;
    for (size_t i = 0; i < c->count; ++i) c->best[i] = c->pose[c->joints[i]];
}

/* Go back to the best pose seen if the current one is worse; returns the resulting error. */
static inline float akp_ik_restore_best(akp_ik_chain* c, float error) {
    if (!(error > c->best_error)) return error;
    for (size_t i = 0; i < c->count; ++i) c->pose[c->joints[i]] = c->best[i];
    akp_ik_fk(c, 0);
    return c->best_error;
}

/* Clamp a local transform's rotation (a prism joint's slide) to the joint's limits. Unlike
 * ak_skeleton_limit_joint alone, the translation of a rotating joint is kept as it is (an
 * animated pose may move it off the rest value; IK must not change bone lengths). */
static inline ak_transform akp_ik_limit(const ak_skeleton* sk, size_t joint, ak_transform local) {
    ak_transform r = ak_skeleton_limit_joint(sk, joint, local);
    if (ak_skeleton_joint_type(sk, joint) != AK_JOINT_PRISM) r.translation = local.translation;
    return r;
}

/* Angle of a hinge joint's local rotation about its axis, relative to its rest rotation. */
static inline float akp_ik_hinge_angle(const ak_skeleton* sk, size_t joint, ak_quat local) {
    const ak_quat rel = ak_quat_mul(ak_quat_conjugate(ak_skeleton_rest_pose(sk).ptr[joint].rotation), local);
    const ak_vec3 axis = ak_skeleton_joint_limits(sk, joint).axis;
    return 2.0f * atan2f(rel.x * axis.x + rel.y * axis.y + rel.z * axis.z, rel.w);
}

/* Joint type as the solver sees it: FREE when limits are ignored. */
static inline ak_joint_type akp_ik_type(const akp_ik_chain* c, size_t i) { return (ak_joint_type)c->types[i]; }

/* Set chain joint i's local rotation so that its model rotation becomes world_rot, then clamp
 * to its limits. world[i] is updated; descendants are not. */
static inline void akp_ik_set_world_rot(akp_ik_chain* c, size_t i, ak_quat world_rot) {
    const size_t j = (size_t)c->joints[i];
    ak_transform* l = &c->pose[j];
    l->rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(akp_ik_parent_rot(c, i)), world_rot));
    if (c->clamp[i]) *l = akp_ik_limit(c->skeleton, j, *l);
    c->world[i] = akp_ik_compose(akp_ik_parent_world(c, i), *l);
}

/* Rotate chain joint i by the model-space rotation q (about its own position). */
static inline void akp_ik_rotate(akp_ik_chain* c, size_t i, ak_quat q) {
    akp_ik_set_world_rot(c, i, ak_quat_mul(q, c->world[i].rotation));
}

/* Quaternion of a rotation vector (axis * angle, radians). */
static inline ak_quat akp_quat_from_rotvec(ak_vec3 w) {
    float a = ak_vec3_length(w);
    if (a < 1e-12f) return ak_quat_normalize(ak_quat_make(0.5f * w.x, 0.5f * w.y, 0.5f * w.z, 1.0f));
    float s = sinf(0.5f * a) / a;
    return ak_quat_make(w.x * s, w.y * s, w.z * s, cosf(0.5f * a));
}

/* Rotation vector (axis * angle in [0, pi]) of a unit quaternion. */
static inline ak_vec3 akp_quat_to_rotvec(ak_quat q) {
    if (q.w < 0.0f) q = ak_quat_neg(q);
    ak_vec3 v = ak_vec3_make(q.x, q.y, q.z);
    float s = ak_vec3_length(v);
    if (s < 1e-12f) return ak_vec3_scale(v, 2.0f);
    return ak_vec3_scale(v, 2.0f * atan2f(s, q.w) / s);
}

/* Angle in [0, pi] of a unit quaternion's rotation. */
static inline float akp_quat_angle(ak_quat q) {
    float s = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z);
    return 2.0f * atan2f(s, fabsf(q.w));
}

/* Half-angle quaternion about unit axis from the full angle's (cos, sin), c^2 + s^2 = 1. The
 * larger of cos(a/2), sin(a/2) comes from a square root and the other from
 * sin(a) = 2 sin(a/2) cos(a/2), so small angles keep their precision (sqrt(1 - c) alone
 * would quantise them to ~3e-4 rad in float). */
static inline ak_quat akp_quat_half_angle(ak_vec3 axis, float c, float s) {
    float ch, sh;
    if (c >= 0.0f) {
        ch = sqrtf(0.5f + 0.5f * c);
        sh = 0.5f * s / ch;
    } else {
        sh = sqrtf(0.5f - 0.5f * c);
        if (s < 0.0f) sh = -sh;
        ch = 0.5f * s / sh;
    }
    return ak_quat_make(axis.x * sh, axis.y * sh, axis.z * sh, ch);
}

/* Rotation (model space) that turns re towards rd, limited to max_step radians (>= pi: no
 * limit); for a hinge, about its unit axis only (both vectors projected onto the plane of
 * rotation). Opposite vectors turn half a turn about any normal; zero vectors give the
 * identity. Unlimited, it is the shortest-arc quaternion (cross, |re||rd| + dot), normalised:
 * two square roots, no trig. */
static inline ak_quat akp_ik_aim_rotation(ak_vec3 re, ak_vec3 rd, bool hinge, ak_vec3 axis, float max_step) {
    if (hinge) {
        re = ak_vec3_madd(re, axis, -ak_vec3_dot(re, axis));
        rd = ak_vec3_madd(rd, axis, -ak_vec3_dot(rd, axis));
    }
    const float l2 = ak_vec3_length_sq(re) * ak_vec3_length_sq(rd);
    if (!(l2 > 1e-24f)) return ak_quat_identity();
    const float m = sqrtf(l2), d = ak_vec3_dot(re, rd);
    ak_vec3 v = ak_vec3_cross(re, rd);
    if (hinge) v = ak_vec3_scale(axis, ak_vec3_dot(v, axis));
    if (max_step < AK_PI) {
        const float c = d / m, cmax = cosf(max_step);
        if (c < cmax) { /* limit the turn, keeping its axis */
            ak_vec3 ax = ak_vec3_normalize(v);
            if (ak_vec3_length_sq(ax) == 0.0f) ax = hinge ? axis : ak_vec3_any_perpendicular(re);
            return akp_quat_half_angle(ax, cmax, sinf(max_step));
        }
    }
    const float w = m + d;
    if (w < 1e-6f * m) { /* opposite */
        ak_vec3 ax = hinge ? axis : ak_vec3_any_perpendicular(re);
        return ak_quat_make(ax.x, ax.y, ax.z, 0.0f);
    }
    const float inv = 1.0f / sqrtf(ak_vec3_length_sq(v) + w * w);
    return ak_quat_make(v.x * inv, v.y * inv, v.z * inv, w * inv);
}

/* When the chain is straight and the target lies on its line inside the reach (the singular
 * configuration of CCD, FABRIK and DLS), bend it in one plane towards the side its hinges
 * allow, effector back on the line (chain.c); returns whether it did. world[] consistent.
 * off_line: the target need only be inside the reach (nearer the root than the chain's
 * length), on the line or not, and a nearly straight chain (joints within 1e-3 of its length
 * off the line) counts as straight; the root then turns the effector onto the target's ray. */
bool akp_ik_unstraighten(akp_ik_chain* c, bool off_line);

/* Solvers (src/ik/<name>.c). Each starts from a chain whose world[] is current and returns
 * with world[] and the pose consistent. */
akp_ik_outcome akp_ik_ccd(akp_ik_chain* c, const ak_ik_chain_job* job);
/* One CCD sweep over the chain (world[] consistent before and after). */
void akp_ik_ccd_sweep(akp_ik_chain* c, float max_step, bool from_root);
/* positions, previous: [count] scratch (the previous pass's positions, for the momentum step). */
akp_ik_outcome akp_ik_fabrik(akp_ik_chain* c, const ak_ik_chain_job* job, ak_vec3* positions, ak_vec3* previous,
                             float* lengths);
akp_ik_outcome akp_ik_dls(akp_ik_chain* c, const ak_ik_chain_job* job, void* scratch);
size_t akp_ik_dls_scratch_size(size_t chain_count);
void akp_ik_two_bone_chain(akp_ik_chain* c, const ak_ik_chain_job* job);

/* The analytic two-bone core shared by the job and the chain solver. branch 0 picks the bend
 * closest to the current one, 1 the other (both ignored when job->mid_axis_signed applies: the
 * side mid_axis sets). Returns whether the target was within reach. */
bool akp_ik_two_bone_solve(const ak_ik_two_bone_job* job, int branch, ak_quat* out_start, ak_quat* out_mid);

#endif
