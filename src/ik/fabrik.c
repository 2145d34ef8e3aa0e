/* FABRIK (Aristidou & Lasenby 2011): forward and backward reaching on joint positions, then
 * the positions turned back into rotations. A bone's new rotation is the shortest arc from its
 * current direction to the new one, so each joint keeps its twist about the bone.
 *
 * Chains without limits iterate on positions alone and convert once at the end. With limits
 * (any non-FREE joint), every iteration converts to rotations, clamps each joint to its limits
 * and reads the positions back by forward kinematics, so the next pass starts from a pose
 * the joints can take. The tree job always does the latter. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "ik_internal.h"

/* p_from + len * unit(towards - p_from); the fallback direction when they coincide. */
static ak_vec3 reach(ak_vec3 p_from, ak_vec3 towards, float len, ak_vec3 fallback) {
    ak_vec3 d = ak_vec3_sub(towards, p_from);
    float l2 = ak_vec3_length_sq(d);
    if (!(l2 > 1e-30f)) return ak_vec3_madd(p_from, fallback, len);
    return ak_vec3_madd(p_from, d, len / sqrtf(l2));
}

/* Turn joint i so its child (chain joint i + 1) points at desired; world[i + 1] is rebuilt. */
static void aim_bone(akp_ik_chain* c, size_t i, ak_vec3 desired) {
    const ak_vec3 p = c->world[i].translation;
    const ak_transform child_local = c->pose[c->joints[i + 1]];
    ak_vec3 cur = ak_quat_rotate(c->world[i].rotation, ak_vec3_mul(c->world[i].scale, child_local.translation));
    ak_vec3 want = ak_vec3_sub(desired, p);
    const ak_joint_type type = akp_ik_type(c, i);
    if (type == AK_JOINT_HINGE) {
        ak_vec3 axis = ak_vec3_normalize(
            ak_quat_rotate(c->world[i].rotation, ak_skeleton_joint_limits(c->skeleton, (size_t)c->joints[i]).axis));
        akp_ik_rotate(c, i, akp_ik_aim_rotation(cur, want, true, axis, AK_PI));
    } else if (type != AK_JOINT_PRISM && ak_vec3_length_sq(cur) > 1e-24f && ak_vec3_length_sq(want) > 1e-24f) {
        akp_ik_rotate(c, i, ak_quat_from_to(cur, want));
    }
    c->world[i + 1] = akp_ik_compose(c->world[i], child_local);
}

/* Positions -> rotations for the whole chain, root first; world[] ends consistent. */
static void positions_to_rotations(akp_ik_chain* c, const ak_vec3* pos) {
    for (size_t i = 0; i + 1 < c->count; ++i) aim_bone(c, i, pos[i + 1]);
}

static bool chain_has_limits(const akp_ik_chain* c) {
    for (size_t i = 0; i < c->count; ++i)
        if (c->types[i] != AK_JOINT_FREE) return true;
    return false;
}

/* One FABRIK iteration. Unconstrained: on positions only. Constrained: the backward pass goes
 * through rotations: each joint turns (within its limits) to aim its bone from where it really
 * is at the forward-pass spot, and the child lands where forward kinematics puts it; then a
 * constrained CCD sweep, because a joint held at a limit can leave the passes at a fixed point
 * short of the target, and the sweep lets its neighbours take up the slack. */
static void fabrik_pass(akp_ik_chain* c, ak_vec3* pos, const float* len, float total, ak_vec3 root, bool constrained) {
    const size_t n = c->count, last = n - 1;
    const ak_vec3 t = c->target;
    if (ak_vec3_distance(root, t) >= total) {
        /* Out of reach: stretch the chain straight towards the target. */
        for (size_t i = 0; i < last; ++i) {
            ak_vec3 fallback = ak_vec3_normalize(ak_vec3_sub(pos[i + 1], pos[i]));
            pos[i + 1] = reach(pos[i], t, len[i], fallback);
        }
    } else {
        /* Forward reaching: effector onto the target, then each joint towards its child. */
        pos[last] = t;
        for (size_t i = last; i-- > 0;) {
            ak_vec3 fallback = ak_vec3_normalize(ak_vec3_sub(c->world[i].translation, c->world[i + 1].translation));
            pos[i] = reach(pos[i + 1], pos[i], len[i], fallback);
        }
        /* Backward reaching: the root back in place, then each child towards its new spot. */
        pos[0] = root;
        if (!constrained) {
            for (size_t i = 0; i < last; ++i) {
                ak_vec3 fallback = ak_vec3_normalize(ak_vec3_sub(c->world[i + 1].translation, c->world[i].translation));
                pos[i + 1] = reach(pos[i], pos[i + 1], len[i], fallback);
            }
        }
    }
    if (constrained) {
        positions_to_rotations(c, pos);
        /* Limits can turn the passes' answer into a worse pose than the best one met (a bend
         * the hinges refuse comes back straight): sweep from the best pose then. */
        akp_ik_restore_best(c, ak_vec3_distance(c->world[last].translation, t));
        akp_ik_ccd_sweep(c, AK_PI, false);
        for (size_t i = 0; i < n; ++i) pos[i] = c->world[i].translation;
    }
}

/* Chains with limits first try the plain passes (often the answer already respects the limits,
 * e.g. a planar chain of hinges); only if the converted pose misses do the constrained
 * iterations take over for the rest of the budget. */
akp_ik_outcome akp_ik_fabrik(akp_ik_chain* c, const ak_ik_chain_job* job, ak_vec3* pos, ak_vec3* prev, float* len) {
    const size_t n = c->count, last = n - 1;
    const ak_vec3 t = c->target;
    for (size_t i = 0; i < n; ++i) pos[i] = c->world[i].translation;
    float total = 0.0f;
    for (size_t i = 0; i < last; ++i) total += (len[i] = ak_vec3_distance(pos[i + 1], pos[i]));
    const ak_vec3 root = pos[0];
    const bool limited = chain_has_limits(c);
    const float noise = 1e-6f * ak_maxf(total, 1e-6f);
    akp_ik_outcome out = {ak_vec3_distance(pos[last], t), 0};
    bool constrained = false;
    int rebends = 0;
    for (;;) {
        float best = out.error;
        int stalled = 0;
        /* On positions, aim a little inside the tolerance: turning the positions back into
         * rotations adds float round-off, which must not push a converged answer out. */
        const float goal = constrained ? c->tolerance : 0.9f * c->tolerance;
        float prev_error = out.error;
        while (out.error > goal && out.iterations < job->max_iterations) {
            /* Near full reach the passes converge linearly and slowly (each one straightens
             * the chain a little). While the error shrinks by less than half per pass, start
             * the next pass from the last one extrapolated by its own step (a momentum step
             * on the positions); the passes restore the bone lengths, so only where they
             * start changes. Positions only: the constrained iterations go through limits. */
            if (!constrained && out.iterations >= 2 && out.error > 0.5f * prev_error) {
                for (size_t i = 1; i < n; ++i) {
                    const ak_vec3 x = pos[i];
                    pos[i] = ak_vec3_add(x, ak_vec3_sub(x, prev[i]));
                    prev[i] = x;
                }
            } else {
                memcpy(prev, pos, n * sizeof *pos);
            }
            prev_error = out.error;
            fabrik_pass(c, pos, len, total, root, constrained);
            out.error = ak_vec3_distance(pos[last], t);
            ++out.iterations;
            if (constrained) akp_ik_track_best(c, out.error);
            if (out.error < best - noise) {
                best = out.error;
                stalled = 0;
            } else if (++stalled >= 3) {
                /* Constrained and stuck (nearly) straight, the target inside the reach on or
                 * near the line: bend again. */
                if (constrained && rebends < 2 && akp_ik_unstraighten(c, true)) {
                    ++rebends;
                    stalled = 0;
                    for (size_t i = 0; i < n; ++i) pos[i] = c->world[i].translation;
                    best = out.error = ak_vec3_distance(pos[last], t);
                    continue;
                }
                break;
            }
        }
        if (constrained) break;
        if (out.iterations > 0) positions_to_rotations(c, pos);
        out.error = ak_vec3_distance(c->world[last].translation, t);
        if (!limited) break;
        akp_ik_track_best(c, out.error);
        if (out.error <= c->tolerance || out.iterations >= job->max_iterations) break;
        constrained = true;
        /* The plain passes need not bend the way the limits allow (from a nearly straight
         * chain, the forward pass folds the last bones back, zigzagging): when the converted
         * answer is worse than the input, the constrained iterations start from the input;
         * when it came back (nearly) straight with the target inside the reach, bend it
         * the allowed way. */
        out.error = akp_ik_restore_best(c, out.error);
        akp_ik_unstraighten(c, true);
        for (size_t i = 0; i < n; ++i) pos[i] = c->world[i].translation;
    }
    out.error = akp_ik_restore_best(c, out.error);
    return out;
}

/* ---- trees ----------------------------------------------------------------------------- */

/* Scratch layout of the tree job, per joint of the skeleton. */
typedef struct tree_mem {
    ak_transform* world;
    ak_vec3* pos;   /* current (FK) positions */
    ak_vec3* fwd;   /* forward-pass positions */
    ak_vec3* sum;   /* sub-base centroid accumulators */
    float* len;     /* bone length to the parent */
    int32_t* count; /* proposals received (forward pass) */
    int32_t* target; /* effector slot, or -1 */
    int32_t* first_child;
    int32_t* next_sibling;
    int32_t* nodes; /* tree joints, ascending (parents first) */
    ak_vec3* goal;  /* [effector count] targets in the solve's frame */
} tree_mem;

static size_t tree_layout(size_t n, unsigned char* base, tree_mem* m) {
    size_t off = 0;
#define AKP_CARVE(field, type)                                                  \
    do {                                                                        \
        if (m) m->field = (type*)(base + off);                                  \
        off += akp_align16(n * sizeof(type));                                   \
    } while (0)
    AKP_CARVE(world, ak_transform);
    AKP_CARVE(pos, ak_vec3);
    AKP_CARVE(fwd, ak_vec3);
    AKP_CARVE(sum, ak_vec3);
    AKP_CARVE(len, float);
    AKP_CARVE(count, int32_t);
    AKP_CARVE(target, int32_t);
    AKP_CARVE(first_child, int32_t);
    AKP_CARVE(next_sibling, int32_t);
    AKP_CARVE(nodes, int32_t);
    AKP_CARVE(goal, ak_vec3);
#undef AKP_CARVE
    return off;
}

size_t ak_ik_fabrik_tree_scratch_size(size_t joint_count) {
    return 16 + tree_layout(joint_count ? joint_count : 1, NULL, NULL);
}

ak_result ak_ik_fabrik_tree_validate(const ak_ik_fabrik_tree_job* job) {
    if (!job || !job->skeleton || !job->pose.ptr || !job->effectors.ptr || !job->targets.ptr ||
        job->effectors.count == 0)
        return AK_ERR_NULL_ARG;
    const size_t n = ak_skeleton_joint_count(job->skeleton);
    if (job->pose.count < n || job->targets.count < job->effectors.count) return AK_ERR_SPAN_SMALL;
    if (job->root_joint < 0 || (size_t)job->root_joint >= n) return AK_ERR_BAD_INDEX;
    ak_i32_cspan parents = ak_skeleton_parents(job->skeleton);
    for (size_t k = 0; k < job->effectors.count; ++k)
        if (job->effectors.ptr[k] < 0 || (size_t)job->effectors.ptr[k] >= n) return AK_ERR_BAD_INDEX;
    for (size_t k = 0; k < job->effectors.count; ++k)
        for (size_t m = k + 1; m < job->effectors.count; ++m)
            if (job->effectors.ptr[k] == job->effectors.ptr[m]) return AK_ERR_DUPLICATE;
    for (size_t k = 0; k < job->effectors.count; ++k) {
        int j = job->effectors.ptr[k];
        while (j >= 0 && j != job->root_joint) j = parents.ptr[j];
        if (j < 0) return AK_ERR_NOT_FOUND;
    }
    for (size_t k = 0; k < job->effectors.count; ++k)
        if (!ak_vec3_is_finite(job->targets.ptr[k])) return AK_ERR_BAD_DATA;
    for (int p = job->root_joint; p >= 0; p = parents.ptr[p])
        if (!ak_transform_is_finite(job->pose.ptr[p])) return AK_ERR_BAD_DATA;
    for (size_t j = (size_t)job->root_joint; j < n; ++j)
        if (!ak_transform_is_finite(job->pose.ptr[j])) return AK_ERR_BAD_DATA;
    /* Finite locals can still overflow on the way to model space (bones of 3e38 end to end). */
    for (size_t k = 0; k < job->effectors.count; ++k) {
        ak_transform acc = ak_transform_identity();
        for (int p = job->effectors.ptr[k]; p >= 0; p = parents.ptr[p]) {
            /* (through a named local: clang 14 with ASan and libFuzzer's coverage counters
             * reported the returned temporary as used after its scope here) */
            const ak_transform next = ak_transform_mul(job->pose.ptr[p], acc);
            if (!ak_transform_is_finite(next)) return AK_ERR_BAD_DATA;
            acc = next;
        }
    }
    if (!(job->tolerance >= 0.0f && ak_finitef(job->tolerance))) return AK_ERR_BAD_ARG;
    if (!job->scratch.ptr) return AK_ERR_NULL_ARG;
    if (job->scratch.count < ak_ik_fabrik_tree_scratch_size(n)) return AK_ERR_SPAN_SMALL;
    return AK_OK;
}

/* Best rotation taking the vectors from[k] onto the directions of to[k] (least squares),
 * refined from an initial guess by the torque iteration of Mueller et al. 2016. */
static ak_quat fit_rotation(const ak_vec3* from, const ak_vec3* to, size_t count) {
    ak_quat q = ak_quat_from_to(from[0], to[0]);
    if (count < 2) return q;
    for (int it = 0; it < 16; ++it) {
        ak_vec3 torque = ak_vec3_zero();
        float dots = 0.0f;
        for (size_t k = 0; k < count; ++k) {
            ak_vec3 r = ak_quat_rotate(q, from[k]);
            torque = ak_vec3_add(torque, ak_vec3_cross(r, to[k]));
            dots += ak_vec3_dot(r, to[k]);
        }
        ak_vec3 w = ak_vec3_scale(torque, 1.0f / (fabsf(dots) + 1e-20f));
        if (ak_vec3_length_sq(w) < 1e-14f) break;
        q = ak_quat_normalize(ak_quat_mul(akp_quat_from_rotvec(w), q));
    }
    return q;
}

ak_result ak_ik_fabrik_tree_run(const ak_ik_fabrik_tree_job* job) {
    ak_result res = ak_ik_fabrik_tree_validate(job);
    if (res != AK_OK) return res;
    const ak_skeleton* sk = job->skeleton;
    const size_t n = ak_skeleton_joint_count(sk);
    const int32_t* parents = ak_skeleton_parents(sk).ptr;
    ak_transform* pose = job->pose.ptr;
    const bool limits = !job->ignore_limits;
    const size_t max_iterations = job->max_iterations ? job->max_iterations : 50u;
    const int root = job->root_joint;
    tree_mem m;
    tree_layout(n, (unsigned char*)(((uintptr_t)job->scratch.ptr + 15u) & ~(uintptr_t)15u), &m);

    /* Mark the tree: every joint on a path from an effector up to the root. */
    for (size_t j = 0; j < n; ++j) {
        m.target[j] = -1;
        m.count[j] = 0; /* reused as the tree mark here */
        m.first_child[j] = m.next_sibling[j] = -1;
    }
    for (size_t k = 0; k < job->effectors.count; ++k) {
        m.target[job->effectors.ptr[k]] = (int32_t)k;
        for (int j = job->effectors.ptr[k]; j != root; j = parents[j]) m.count[j] = 1;
    }
    m.count[root] = 1;
    size_t node_count = 0;
    for (size_t j = (size_t)root; j < n; ++j)
        if (m.count[j]) m.nodes[node_count++] = (int32_t)j;
    for (size_t k = node_count; k-- > 1;) { /* children lists, in ascending order */
        int j = m.nodes[k], p = parents[j];
        m.next_sibling[j] = m.first_child[p];
        m.first_child[p] = (int32_t)j;
    }

    /* Forward kinematics of the tree. */
    ak_transform base = ak_transform_identity();
    for (int p = parents[root]; p >= 0; p = parents[p]) base = ak_transform_mul(pose[p], base);
    /* As for chains (chain.c): solve in a frame centred on the root joint and scaled by a
     * power of two that brings the tree's extent into [0.5, 1), so no squared distance
     * overflows or vanishes; targets farther than 1e6 extents move onto their ray. */
    for (size_t k = 0; k < node_count; ++k) {
        int j = m.nodes[k];
        m.world[j] = ak_transform_mul(k == 0 ? base : m.world[parents[j]], pose[j]);
    }
    const ak_vec3 origin = m.world[root].translation;
    double extent = 0.0;
    for (size_t k = 1; k < node_count; ++k) {
        const ak_vec3 p = m.world[m.nodes[k]].translation;
        extent = fmax(extent, fmax(fabs((double)p.x - origin.x), fmax(fabs((double)p.y - origin.y), fabs((double)p.z - origin.z))));
    }
    int exponent = 0;
    if (extent > 0.0) frexp(extent, &exponent);
    const double scale = ldexp(1.0, exponent), inv = 1.0 / scale;
    base.translation = ak_vec3_make((float)(((double)base.translation.x - origin.x) * inv),
                                    (float)(((double)base.translation.y - origin.y) * inv),
                                    (float)(((double)base.translation.z - origin.z) * inv));
    base.scale = ak_vec3_make((float)(base.scale.x * inv), (float)(base.scale.y * inv), (float)(base.scale.z * inv));
    for (size_t k = 0; k < job->effectors.count; ++k) {
        const ak_vec3 t = job->targets.ptr[k];
        double g[3] = {((double)t.x - origin.x) * inv, ((double)t.y - origin.y) * inv, ((double)t.z - origin.z) * inv};
        const double d = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]), far = 1e6;
        if (d > far)
            for (int c = 0; c < 3; ++c) g[c] *= far / d;
        m.goal[k] = ak_vec3_make((float)g[0], (float)g[1], (float)g[2]);
    }
    float total = 0.0f;
    for (size_t k = 0; k < node_count; ++k) {
        int j = m.nodes[k];
        m.world[j] = ak_transform_mul(k == 0 ? base : m.world[parents[j]], pose[j]);
        m.pos[j] = m.world[j].translation;
        if (k > 0) total += (m.len[j] = ak_vec3_distance(m.pos[j], m.pos[parents[j]]));
    }
    /* in the solve's frame; the default is relative to the tree's length at any scale */
    const float tolerance = job->tolerance > 0.0f ? (float)(job->tolerance * inv) : total > 0.0f ? 1e-4f * total
                                                                                              : (float)(1e-7 * inv);
    const float noise = 1e-6f * ak_maxf(total, 1e-6f);
    const ak_vec3 root_pos = m.pos[root];

    float error = 0.0f;
    for (size_t k = 0; k < job->effectors.count; ++k)
        error = ak_maxf(error, ak_vec3_distance(m.pos[job->effectors.ptr[k]], m.goal[k]));
    float best = error;
    size_t iterations = 0;
    int stalled = 0;
    ak_vec3 from[64], to[64];
    while (error > tolerance && iterations < max_iterations) {
        /* Forward reaching, children before parents: each joint goes to its target, or to the
         * centroid of its children's proposals (a sub-base), then proposes a parent position. */
        for (size_t k = 0; k < node_count; ++k) {
            m.sum[m.nodes[k]] = ak_vec3_zero();
            m.count[m.nodes[k]] = 0;
        }
        for (size_t k = node_count; k-- > 0;) {
            int j = m.nodes[k];
            ak_vec3 p = m.target[j] >= 0 ? m.goal[m.target[j]]
                        : m.count[j] > 0 ? ak_vec3_scale(m.sum[j], 1.0f / (float)m.count[j])
                                         : m.pos[j];
            m.fwd[j] = p;
            if (k == 0) break;
            int par = parents[j];
            ak_vec3 fallback = ak_vec3_normalize(ak_vec3_sub(m.pos[par], m.pos[j]));
            m.sum[par] = ak_vec3_add(m.sum[par], reach(p, m.pos[par], m.len[j], fallback));
            m.count[par]++;
        }
        /* Backward reaching from the fixed root. */
        m.fwd[root] = root_pos;
        for (size_t k = 1; k < node_count; ++k) {
            int j = m.nodes[k], par = parents[j];
            ak_vec3 fallback = ak_vec3_normalize(ak_vec3_sub(m.pos[j], m.pos[par]));
            m.fwd[j] = reach(m.fwd[par], m.fwd[j], m.len[j], fallback);
        }
        /* Back to rotations, parents first, with limits; positions re-read by FK. */
        for (size_t k = 0; k < node_count; ++k) {
            int j = m.nodes[k];
            ak_transform parent_w = k == 0 ? base : m.world[parents[j]];
            m.world[j] = ak_transform_mul(parent_w, pose[j]);
            bool prism = limits && ak_skeleton_joint_type(sk, (size_t)j) == AK_JOINT_PRISM;
            size_t cc = 0;
            for (int ch = m.first_child[j]; ch >= 0 && cc < 64; ch = m.next_sibling[ch]) {
                ak_vec3 cur = ak_quat_rotate(m.world[j].rotation, ak_vec3_mul(m.world[j].scale, pose[ch].translation));
                ak_vec3 want = ak_vec3_sub(m.fwd[ch], m.world[j].translation);
                if (ak_vec3_length_sq(cur) < 1e-24f || ak_vec3_length_sq(want) < 1e-24f) continue;
                from[cc] = cur;
                to[cc] = ak_vec3_scale(ak_vec3_normalize(want), ak_vec3_length(cur));
                ++cc;
            }
            if (cc > 0 && !prism) {
                ak_quat q = fit_rotation(from, to, cc);
                ak_quat wr = ak_quat_mul(q, m.world[j].rotation);
                pose[j].rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(parent_w.rotation), wr));
                if (limits) pose[j] = akp_ik_limit(sk, (size_t)j, pose[j]);
                m.world[j] = ak_transform_mul(parent_w, pose[j]);
            }
            m.pos[j] = m.world[j].translation;
        }
        error = 0.0f;
        for (size_t k = 0; k < job->effectors.count; ++k)
            error = ak_maxf(error, ak_vec3_distance(m.pos[job->effectors.ptr[k]], m.goal[k]));
        ++iterations;
        if (error < best - noise) {
            best = error;
            stalled = 0;
        } else if (++stalled >= 3) {
            break;
        }
    }
    /* The largest error in model units, in double, out of the solve's frame. */
    double error_d = 0.0;
    for (size_t k = 0; k < job->effectors.count; ++k) {
        const ak_vec3 e = m.pos[job->effectors.ptr[k]], t = job->targets.ptr[k];
        const double x = (double)e.x * scale + origin.x - t.x, y = (double)e.y * scale + origin.y - t.y,
                     z = (double)e.z * scale + origin.z - t.z;
        error_d = fmax(error_d, sqrt(x * x + y * y + z * z));
    }
    if (job->out_reached) *job->out_reached = error_d <= (double)tolerance * scale;
    if (job->out_error) *job->out_error = error_d < FLT_MAX ? (float)error_d : FLT_MAX;
    if (job->out_iterations) *job->out_iterations = iterations;
    return AK_OK;
}
