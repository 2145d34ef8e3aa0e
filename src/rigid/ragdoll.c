/* Ragdolls: a capsule per bone of a skeleton, a joint per skeleton joint, and the bodies
 * written back as a skeleton pose. */
#include <math.h>
#include <string.h>

#include <animkit/skeleton.h>

#include "rigid_impl.h"

/* World matrix of joint i: root * local[roots..i], walking up the parents (no storage; a
 * skeleton's parents come before their children, so the walk ends). */
static ak_mat4 joint_world(const ak_skeleton* sk, ak_transform_cspan pose, ak_mat4 root, size_t i) {
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_mat4 m = ak_transform_to_mat4(pose.ptr[i]);
    for (int p = parents.ptr[i]; p >= 0; p = parents.ptr[p])
        m = ak_mat4_mul(ak_transform_to_mat4(pose.ptr[p]), m);
    return ak_mat4_mul(root, m);
}

/* Rotation of a matrix whose columns may carry a scale. */
static ak_quat mat_rotation(ak_mat4 m) {
    ak_mat3 r = ak_mat4_to_mat3(m);
    ak_vec3 c0 = ak_vec3_normalize(ak_mat3_col(r, 0)), c1 = ak_vec3_normalize(ak_mat3_col(r, 1)),
            c2 = ak_vec3_normalize(ak_mat3_col(r, 2));
    return ak_quat_normalize(ak_quat_from_mat3(ak_mat3_from_cols(c0, c1, c2)));
}

static bool has_children(const ak_skeleton* sk, size_t i) {
    return ak_skeleton_child_count(sk, i) > 0;
}

/* Mean world position of joint i's children. */
static ak_vec3 children_mean(const ak_skeleton* sk, ak_transform_cspan pose, ak_mat4 root,
                             size_t i) {
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_vec3 sum = ak_vec3_zero();
    float n = 0.0f;
    for (size_t c = i + 1; c < parents.count; ++c)
        if (parents.ptr[c] == (int32_t)i) {
            sum = ak_vec3_add(sum, ak_mat4_get_translation(joint_world(sk, pose, root, c)));
            n += 1.0f;
        }
    return n > 0.0f ? ak_vec3_scale(sum, 1.0f / n)
                    : ak_mat4_get_translation(joint_world(sk, pose, root, i));
}

size_t ak_rigid_ragdoll_body_count(const ak_skeleton* sk) {
    size_t n = sk ? ak_skeleton_joint_count(sk) : 0, count = 0;
    for (size_t i = 0; i < n; ++i) count += has_children(sk, i);
    return count;
}

size_t ak_rigid_ragdoll_joint_count(const ak_skeleton* sk) {
    size_t n = sk ? ak_skeleton_joint_count(sk) : 0, count = 0;
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    for (size_t i = 0; i < n; ++i) count += has_children(sk, i) && parents.ptr[i] >= 0;
    return count;
}

/* A body's pose for joint i: centred on the bone, local Y along it. */
static void bone_body(const ak_skeleton* sk, ak_transform_cspan pose, ak_mat4 root, size_t i,
                      ak_vec3* out_x, ak_quat* out_q, float* out_length) {
    ak_mat4 w = joint_world(sk, pose, root, i);
    ak_vec3 p0 = ak_mat4_get_translation(w), p1 = children_mean(sk, pose, root, i);
    ak_vec3 d = ak_vec3_sub(p1, p0);
    float len = ak_vec3_length(d);
    ak_quat qj = mat_rotation(w);
    if (len < 1e-4f) {
        *out_x = p0;
        *out_q = qj;
        *out_length = 0.0f;
        return;
    }
    /* the joint's frame turned so its Y runs along the bone (keeps the twist of the joint):
     * the turn is found in the joint's frame, so a bone that moves rigidly with its joint
     * gets the same turn in every pose (its velocities then come out right); a bone pointing
     * down the joint's -Y (a leg) is turned half a turn about X first, since from_to is
     * ill-conditioned near opposite vectors */
    ak_vec3 dl = ak_quat_rotate(ak_quat_conjugate(qj), ak_vec3_scale(d, 1.0f / len));
    ak_quat turn;
    if (dl.y > -0.5f) {
        turn = ak_quat_from_to(ak_vec3_make(0.0f, 1.0f, 0.0f), dl);
    } else {
        const ak_quat half = ak_quat_make(1.0f, 0.0f, 0.0f, 0.0f); /* pi about X: Y -> -Y */
        turn = ak_quat_mul(ak_quat_from_to(ak_vec3_make(0.0f, -1.0f, 0.0f), dl), half);
    }
    *out_q = ak_quat_normalize(ak_quat_mul(qj, turn));
    *out_x = ak_vec3_scale(ak_vec3_add(p0, p1), 0.5f);
    *out_length = len;
}

/* The skin's spans: all empty (no skin, false), or consistent (true); *out_r the error. */
static bool skin_given(const ak_rigid_ragdoll_desc* d, size_t joint_count, ak_result* out_r) {
    *out_r = AK_OK;
    if (!d->skin_positions.count && !d->skin_joints.count && !d->skin_weights.count &&
        !d->skin_slot_joints.count && !d->skin_inverse_binds.count && !d->skin_influence_count)
        return false;
    const size_t nv = d->skin_positions.count, k = d->skin_influence_count;
    const size_t slots = d->skin_slot_joints.count;
    if (!d->skin_positions.ptr || !d->skin_joints.ptr || !d->skin_weights.ptr ||
        !d->skin_slot_joints.ptr || !d->skin_inverse_binds.ptr) {
        *out_r = nv || slots ? AK_ERR_NULL_ARG : AK_ERR_BAD_ARG;
        return false;
    }
    if (k < 1 || k > 8 || !slots || !(d->skin_min_weight >= 0.0f && d->skin_min_weight <= 1.0f)) {
        *out_r = AK_ERR_BAD_ARG;
        return false;
    }
    if (d->skin_joints.count / k < nv || d->skin_weights.count / k < nv ||
        d->skin_inverse_binds.count < slots) {
        *out_r = AK_ERR_SPAN_SMALL;
        return false;
    }
    for (size_t s = 0; s < slots; ++s) {
        if (d->skin_slot_joints.ptr[s] < 0 || (size_t)d->skin_slot_joints.ptr[s] >= joint_count) {
            *out_r = AK_ERR_BAD_INDEX;
            return false;
        }
        if (!ak_mat4_is_finite(&d->skin_inverse_binds.ptr[s])) {
            *out_r = AK_ERR_BAD_DATA;
            return false;
        }
    }
    for (size_t v = 0; v < nv; ++v) {
        if (!ak_vec3_is_finite(d->skin_positions.ptr[v])) {
            *out_r = AK_ERR_BAD_DATA;
            return false;
        }
        for (size_t e = 0; e < k; ++e) {
            if (d->skin_joints.ptr[v * k + e] >= slots) {
                *out_r = AK_ERR_BAD_INDEX;
                return false;
            }
            if (!ak_finitef(d->skin_weights.ptr[v * k + e])) {
                *out_r = AK_ERR_BAD_DATA;
                return false;
            }
        }
    }
    return true;
}

/* A capsule fitted to the skin vertices joint i carries, in the frame of its body (x, q: local
 * Y along the bone): the vertices whose heaviest weight (at least the minimum weight) is a slot
 * naming joint i, or one of i's leaf children (a head, a hand: leaves have no body and move with
 * their parent), each posed rigidly with its joint (root * world_j * inverse_bind p). Returns
 * false when fewer than min_vertices qualify; else *out_radius = the mean plus one standard
 * deviation of their distances from the body's Y axis (a round limb's radius; more for a flat
 * torso or a neck that carries a head) and [*out_lo, *out_hi] their extent along it. */
static bool skin_fit(const ak_rigid_ragdoll_desc* d, ak_mat4 root, size_t i, ak_vec3 x, ak_quat q,
                     float* out_radius, float* out_lo, float* out_hi) {
    const ak_skeleton* sk = d->skeleton;
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    const size_t nv = d->skin_positions.count, k = d->skin_influence_count;
    const float wmin = d->skin_min_weight > 0.0f ? d->skin_min_weight : 0.5f;
    const size_t need = d->skin_min_vertices ? d->skin_min_vertices : 8;
    const ak_quat qi = ak_quat_conjugate(q);
    double sum_r = 0.0, sum_rr = 0.0;
    float lo = INFINITY, hi = -INFINITY;
    size_t count = 0;
    for (size_t v = 0; v < nv; ++v) {
        size_t best = 0;
        for (size_t e = 1; e < k; ++e)
            if (d->skin_weights.ptr[v * k + e] > d->skin_weights.ptr[v * k + best]) best = e;
        const uint16_t slot = d->skin_joints.ptr[v * k + best];
        const size_t j = (size_t)d->skin_slot_joints.ptr[slot];
        if (d->skin_weights.ptr[v * k + best] < wmin ||
            !(j == i || (parents.ptr[j] == (int32_t)i && !has_children(sk, j))))
            continue;
        const ak_mat4 m =
            ak_mat4_mul(joint_world(sk, d->local_pose, root, j), d->skin_inverse_binds.ptr[slot]);
        const ak_vec3 p = ak_mat4_transform_point(m, d->skin_positions.ptr[v]);
        const ak_vec3 l = ak_quat_rotate(qi, ak_vec3_sub(p, x));
        const double rr = (double)l.x * l.x + (double)l.z * l.z;
        sum_r += sqrt(rr);
        sum_rr += rr;
        lo = ak_minf(lo, l.y);
        hi = ak_maxf(hi, l.y);
        ++count;
    }
    if (count < need || count == 0) return false;
    const double mean = sum_r / (double)count;
    const float r = (float)(mean + sqrt(fmax(0.0, sum_rr / (double)count - mean * mean)));
    if (!(r > 1e-5f) || !ak_finitef(r) || !ak_finitef(lo) || !ak_finitef(hi)) return false;
    *out_radius = r;
    *out_lo = lo;
    *out_hi = hi;
    return true;
}

static bool mat_is_zero(ak_mat4 m) {
    for (int k = 0; k < 16; ++k)
        if (m.m[k] != 0.0f) return false;
    return true;
}

ak_result ak_rigid_ragdoll_build(const ak_rigid_ragdoll_desc* desc,
                                 ak_rigid_body_desc_span out_bodies,
                                 ak_rigid_joint_desc_span out_joints,
                                 ak_rigid_ragdoll_bone_span out_bones) {
    if (!desc || !desc->skeleton || !desc->local_pose.ptr || !out_bodies.ptr || !out_bones.ptr)
        return AK_ERR_NULL_ARG;
    const ak_skeleton* sk = desc->skeleton;
    size_t n = ak_skeleton_joint_count(sk);
    size_t nb = ak_rigid_ragdoll_body_count(sk), nj = ak_rigid_ragdoll_joint_count(sk);
    if (nj && !out_joints.ptr) return AK_ERR_NULL_ARG;
    if (desc->local_pose.count < n || out_bodies.count < nb || out_joints.count < nj ||
        out_bones.count < n || (desc->previous_pose.count && desc->previous_pose.count < n))
        return AK_ERR_SPAN_SMALL;
    if (desc->previous_pose.count && (!desc->previous_pose.ptr || !(desc->previous_dt > 0.0f)))
        return AK_ERR_BAD_ARG;
    if (desc->radius_scale < 0.0f || desc->max_radius < 0.0f || desc->density < 0.0f ||
        desc->friction < 0.0f)
        return AK_ERR_BAD_ARG;
    if (!ak_pose_is_finite((ak_transform_cspan){desc->local_pose.ptr, n}) ||
        (desc->previous_pose.count &&
         !ak_pose_is_finite((ak_transform_cspan){desc->previous_pose.ptr, n})) ||
        !ak_finitef(desc->previous_dt) || !ak_finitef(desc->radius_scale) ||
        !ak_finitef(desc->max_radius) || !ak_finitef(desc->free_cone_angle) ||
        !ak_finitef(desc->drive_compliance) || !ak_finitef(desc->drive_damping))
        return AK_ERR_BAD_DATA;
    if (desc->free_cone_angle < 0.0f || desc->drive_compliance < 0.0f || desc->drive_damping < 0.0f)
        return AK_ERR_BAD_ARG;
    ak_result skin_r;
    const bool skin = skin_given(desc, n, &skin_r);
    if (skin_r != AK_OK) return skin_r;
    const ak_mat4 root = mat_is_zero(desc->root) ? ak_mat4_identity() : desc->root;
    const float scale = desc->radius_scale > 0.0f ? desc->radius_scale : 0.2f;
    const float rmax = desc->max_radius > 0.0f ? desc->max_radius : 0.1f;
    const uint32_t group = desc->collision_group ? desc->collision_group : 1u;
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    uint32_t k = 0, kj = 0;
    for (size_t i = 0; i < n; ++i) {
        ak_rigid_ragdoll_bone* bone = &out_bones.ptr[i];
        memset(bone, 0, sizeof *bone);
        bone->body = -1;
        bone->rotation = ak_quat_identity();
        if (!has_children(sk, i)) continue;
        ak_vec3 x;
        ak_quat q;
        float len;
        bone_body(sk, desc->local_pose, root, i, &x, &q, &len);
        ak_rigid_body_desc* b = &out_bodies.ptr[k];
        memset(b, 0, sizeof *b);
        /* thick enough for the children's spread (a pelvis between two hips), and at least
         * 0.4 max_radius so no limb is a thousand times lighter than its neighbour */
        float spread = 0.0f;
        for (size_t c = i + 1; c < n; ++c)
            if (parents.ptr[c] == (int32_t)i) {
                ak_vec3 pc = ak_mat4_get_translation(joint_world(sk, desc->local_pose, root, c));
                ak_vec3 d = ak_vec3_sub(pc, children_mean(sk, desc->local_pose, root, i));
                spread = ak_maxf(spread, ak_vec3_length(d));
            }
        float r = ak_minf(rmax, ak_maxf(ak_maxf(scale * len, spread), 0.4f * rmax));
        float half = ak_maxf(0.0f, 0.5f * len - r);
        /* with a skin: the capsule its vertices fit, centred on their extent along the bone */
        float shift = 0.0f, fr, lo, hi;
        if (skin && skin_fit(desc, root, i, x, q, &fr, &lo, &hi)) {
            r = fr;
            shift = 0.5f * (lo + hi);
            half = ak_maxf(0.0f, 0.5f * (hi - lo) - r);
            x = ak_vec3_add(x, ak_quat_rotate(q, ak_vec3_make(0.0f, shift, 0.0f)));
        }
        b->shape.type = AK_RIGID_CAPSULE;
        b->shape.radius = r;
        b->shape.half_height = half;
        b->position = x;
        b->orientation = q;
        b->density = desc->density;
        b->friction = desc->friction;
        b->collision_group = group;
        if (desc->previous_pose.count) {
            ak_vec3 xp;
            ak_quat qp;
            float lp;
            bone_body(sk, desc->previous_pose, root, i, &xp, &qp, &lp);
            xp = ak_vec3_add(xp, ak_quat_rotate(qp, ak_vec3_make(0.0f, shift, 0.0f)));
            b->velocity = ak_vec3_scale(ak_vec3_sub(x, xp), 1.0f / desc->previous_dt);
            ak_quat dq = ak_quat_mul(q, ak_quat_conjugate(qp));
            float f = (dq.w >= 0.0f ? 2.0f : -2.0f) / desc->previous_dt;
            b->angular_velocity = ak_vec3_make(dq.x * f, dq.y * f, dq.z * f);
        }
        ak_mat4 w = joint_world(sk, desc->local_pose, root, i);
        ak_quat qj = mat_rotation(w);
        ak_quat qi = ak_quat_conjugate(q);
        bone->body = (int32_t)(desc->body_offset + k);
        bone->offset = ak_quat_rotate(qi, ak_vec3_sub(ak_mat4_get_translation(w), x));
        bone->rotation = ak_quat_normalize(ak_quat_mul(qi, qj));
        int p = parents.ptr[i];
        if (p >= 0) {
            /* the parent has a child (this joint), so it has a body, built earlier */
            ak_rigid_joint_desc* jd = &out_joints.ptr[kj++];
            memset(jd, 0, sizeof *jd);
            jd->body_a = (uint32_t)out_bones.ptr[p].body;
            jd->body_b = (uint32_t)bone->body;
            jd->anchor = ak_mat4_get_translation(w);
            ak_joint_limits lim = ak_skeleton_joint_limits(sk, i);
            /* the joint's rest frame in the world, at the start pose of its parent */
            ak_quat q_rest = ak_quat_normalize(
                ak_quat_mul(mat_rotation(joint_world(sk, desc->local_pose, root, (size_t)p)),
                            rest.ptr[i].rotation));
            /* powered: drive b's orientation in a's frame towards the start pose's */
            jd->drive = desc->powered;
            jd->drive_compliance = desc->drive_compliance;
            jd->drive_damping = desc->drive_damping;
            jd->drive_target = ak_quat_normalize(ak_quat_mul(
                ak_quat_conjugate(
                    out_bodies.ptr[out_bones.ptr[p].body - desc->body_offset].orientation),
                q));
            switch (ak_skeleton_joint_type(sk, i)) {
            case AK_JOINT_HINGE: {
                ak_vec3 axis = ak_vec3_length_sq(lim.axis) > 0.0f ? ak_vec3_normalize(lim.axis)
                                                                  : ak_vec3_make(1, 0, 0);
                ak_quat rel = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(rest.ptr[i].rotation),
                                                            desc->local_pose.ptr[i].rotation));
                float phi0 =
                    2.0f * atan2f(ak_vec3_dot(ak_vec3_make(rel.x, rel.y, rel.z), axis), rel.w);
                if (phi0 > AK_PI) phi0 -= 2.0f * AK_PI;
                if (phi0 < -AK_PI) phi0 += 2.0f * AK_PI;
                jd->type = AK_RIGID_JOINT_HINGE;
                jd->axis = ak_quat_rotate(q_rest, axis);
                jd->angle_offset = phi0;
                jd->limited = !(lim.min == 0.0f && lim.max == 0.0f);
                jd->lower = lim.min;
                jd->upper = lim.max;
                break;
            }
            case AK_JOINT_BALL: {
                ak_vec3 axis = ak_vec3_length_sq(lim.axis) > 0.0f ? ak_vec3_normalize(lim.axis)
                                                                  : ak_vec3_make(0, 1, 0);
                jd->type = AK_RIGID_JOINT_BALL;
                jd->axis = ak_quat_rotate(q_rest, axis);
                jd->axis_b = ak_quat_rotate(qj, axis);
                jd->limited = lim.cone_angle > 0.0f;
                jd->upper = lim.cone_angle;
                /* the start pose's twist in the skeleton's measure (swing-twist about the axis) */
                ak_quat rel = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(rest.ptr[i].rotation),
                                                            desc->local_pose.ptr[i].rotation));
                ak_quat sw, tw;
                ak_quat_swing_twist(rel, axis, &sw, &tw);
                float t0 = 2.0f * atan2f(ak_vec3_dot(ak_vec3_make(tw.x, tw.y, tw.z), axis), tw.w);
                if (t0 > AK_PI) t0 -= 2.0f * AK_PI;
                if (t0 < -AK_PI) t0 += 2.0f * AK_PI;
                jd->angle_offset = t0;
                jd->twist_limited = !(lim.twist_min == 0.0f && lim.twist_max == 0.0f);
                jd->twist_lower = lim.twist_min;
                jd->twist_upper = lim.twist_max;
                break;
            }
            case AK_JOINT_PRISM:
                jd->type = AK_RIGID_JOINT_PRISMATIC;
                jd->axis = ak_quat_rotate(
                    q_rest, ak_vec3_length_sq(lim.axis) > 0.0f ? lim.axis : ak_vec3_make(1, 0, 0));
                break;
            default: {
                /* free: a ball; with free_cone_angle, its bone's rest direction (towards the
                 * mean of its children's rest offsets) may swing that far */
                jd->type = AK_RIGID_JOINT_BALL;
                if (desc->free_cone_angle > 0.0f) {
                    ak_vec3 dir = ak_vec3_zero();
                    for (size_t c = i + 1; c < n; ++c)
                        if (parents.ptr[c] == (int32_t)i)
                            dir = ak_vec3_add(dir, rest.ptr[c].translation);
                    dir = ak_vec3_length_sq(dir) > 1e-12f ? ak_vec3_normalize(dir)
                                                          : ak_vec3_make(0, 1, 0);
                    jd->axis = ak_quat_rotate(q_rest, dir);
                    jd->axis_b = ak_quat_rotate(qj, dir);
                    jd->limited = true;
                    jd->upper = desc->free_cone_angle;
                }
                break;
            }
            }
        }
        ++k;
    }
    return AK_OK;
}

ak_result ak_rigid_ragdoll_drive_targets(const ak_skeleton* sk, ak_rigid_ragdoll_bone_cspan bones,
                                         ak_transform_cspan pose, ak_quat_span out) {
    if (!sk || !bones.ptr || !pose.ptr || (!out.ptr && out.count)) return AK_ERR_NULL_ARG;
    const size_t n = ak_skeleton_joint_count(sk);
    if (bones.count < n || pose.count < n || out.count < ak_rigid_ragdoll_joint_count(sk))
        return AK_ERR_SPAN_SMALL;
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
        /* the build's order: a joint per joint with a body and a parent */
        if (!has_children(sk, i) || parents.ptr[i] < 0) continue;
        const ak_rigid_ragdoll_bone* bi = &bones.ptr[i];
        const ak_rigid_ragdoll_bone* bp = &bones.ptr[parents.ptr[i]];
        if (bi->body < 0 || bp->body < 0) return AK_ERR_BAD_INDEX;
        if (!ak_quat_is_finite(pose.ptr[i].rotation)) return AK_ERR_BAD_DATA;
        /* body = joint world rotation * bone.rotation^-1, and joint i's world rotation is its
         * parent's times its local one: a^-1 b = bp.rotation local bi.rotation^-1 */
        out.ptr[k++] = ak_quat_normalize(
            ak_quat_mul(ak_quat_mul(bp->rotation, ak_quat_normalize(pose.ptr[i].rotation)),
                        ak_quat_conjugate(bi->rotation)));
    }
    return AK_OK;
}

ak_result ak_rigid_ragdoll_pose(const ak_skeleton* sk, ak_rigid_ragdoll_bone_cspan bones,
                                ak_mat4 root, ak_vec3_cspan x, ak_quat_cspan q,
                                ak_transform_cspan fallback, ak_transform_span out) {
    if (!sk || !bones.ptr || !x.ptr || !q.ptr || !fallback.ptr || !out.ptr) return AK_ERR_NULL_ARG;
    size_t n = ak_skeleton_joint_count(sk);
    if (bones.count < n || fallback.count < n || out.count < n) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i)
        if (bones.ptr[i].body >= 0 &&
            ((size_t)bones.ptr[i].body >= x.count || (size_t)bones.ptr[i].body >= q.count))
            return AK_ERR_BAD_INDEX;
    if (mat_is_zero(root)) root = ak_mat4_identity();
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    /* world rotation and position of each joint with a body; the others follow their parent
     * (parents come first, so one forward pass; out holds locals, world values are rebuilt
     * from the bodies each time they are needed) */
    for (size_t i = 0; i < n; ++i) {
        const ak_rigid_ragdoll_bone* b = &bones.ptr[i];
        if (b->body < 0) {
            out.ptr[i] = fallback.ptr[i];
            continue;
        }
        ak_quat qb = ak_quat_normalize(q.ptr[b->body]);
        ak_vec3 pw = ak_vec3_add(x.ptr[b->body], ak_quat_rotate(qb, b->offset));
        ak_quat rw = ak_quat_normalize(ak_quat_mul(qb, b->rotation));
        ak_mat4 parent_world = root;
        int p = parents.ptr[i];
        if (p >= 0) {
            const ak_rigid_ragdoll_bone* pb = &bones.ptr[p];
            ak_quat qp = ak_quat_normalize(q.ptr[pb->body]);
            ak_vec3 ppw = ak_vec3_add(x.ptr[pb->body], ak_quat_rotate(qp, pb->offset));
            ak_quat prw = ak_quat_normalize(ak_quat_mul(qp, pb->rotation));
            parent_world = ak_mat4_mul(ak_mat4_translation(ppw), ak_mat4_from_quat(prw));
        }
        /* local = parent_world^-1 * world (rigid, so the inverse is the transpose) */
        ak_mat4 inv =
            ak_mat4_transpose(ak_mat4_from_mat3(ak_mat4_to_mat3(parent_world), ak_vec3_zero()));
        ak_vec3 t =
            ak_mat4_transform_vector(inv, ak_vec3_sub(pw, ak_mat4_get_translation(parent_world)));
        ak_quat pr = p >= 0 ? mat_rotation(parent_world) : mat_rotation(root);
        out.ptr[i].translation = t;
        out.ptr[i].rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(pr), rw));
        out.ptr[i].scale = fallback.ptr[i].scale;
    }
    return AK_OK;
}
