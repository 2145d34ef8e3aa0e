/* Cyclic coordinate descent, as the course gives it: for each joint from the one nearest the
 * end effector up to the root, rotate the joint so that the vector from it to the effector
 * (RE) points along the vector from it to the target (RD); repeat until the effector is within
 * tolerance or the budget is spent.
 *
 * One sweep is O(n): visiting tip to root, the ancestors of the current joint are untouched,
 * so its world transform stays valid and only the effector position needs updating (by the
 * rotation actually applied, after limits). Visiting root to tip, the next joint's world
 * transform is rebuilt from the joint just changed. */
#include "ik_internal.h"

/* normalize(conj(parent) * q * world): a joint's new local rotation after the model-space turn
 * q (q need not be unit). In SSE registers, the two products take about a third of the
 * scalar instructions. */
static inline ak_quat local_after_turn(ak_quat parent, ak_quat q, ak_quat world) {
#if AK_SIMD_SSE2
    const __m128 pc = _mm_xor_ps(_mm_loadu_ps(&parent.x), _mm_set_ps(0.0f, -0.0f, -0.0f, -0.0f));
    const __m128 r = akp_ik_qmul_sse(pc, akp_ik_qmul_sse(_mm_loadu_ps(&q.x), _mm_loadu_ps(&world.x)));
    const __m128 n2 = _mm_mul_ps(r, r);
    const float s = _mm_cvtss_f32(_mm_add_ss(_mm_add_ss(n2, AKP_SIMD_SPLAT(n2, 1)), _mm_add_ss(AKP_SIMD_SPLAT(n2, 2), AKP_SIMD_SPLAT(n2, 3))));
    ak_quat out;
    if (!(s > 1e-30f) || !ak_finitef(s)) return ak_quat_identity();
    _mm_storeu_ps(&out.x, _mm_mul_ps(r, _mm_set1_ps(1.0f / sqrtf(s))));
    return out;
#else
    return ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(parent), ak_quat_mul(q, world)));
#endif
}

/* Slide a prism joint so that the effector moves as close to the target as its axis allows.
 * Returns the effector's displacement. */
static ak_vec3 ccd_slide(akp_ik_chain* c, size_t i, ak_vec3 effector) {
    const size_t j = (size_t)c->joints[i];
    const ak_transform parent = akp_ik_parent_world(c, i);
    const ak_transform rest = ak_skeleton_rest_pose(c->skeleton).ptr[j];
    const ak_joint_limits lim = ak_skeleton_joint_limits(c->skeleton, j);
    ak_vec3 axis_p = ak_quat_rotate(rest.rotation, lim.axis); /* parent space, unit */
    ak_vec3 axis_m = ak_quat_rotate(parent.rotation, ak_vec3_mul(parent.scale, axis_p));
    float a2 = ak_vec3_length_sq(axis_m);
    if (!(a2 > 1e-24f)) return ak_vec3_zero();
    float s = ak_vec3_dot(ak_vec3_sub(c->target, effector), axis_m) / a2; /* parent units */
    ak_vec3 before = c->world[i].translation;
    ak_transform* l = &c->pose[j];
    l->translation = ak_vec3_madd(l->translation, axis_p, s);
    *l = akp_ik_limit(c->skeleton, j, *l);
    c->world[i] = akp_ik_compose(parent, *l);
    return ak_vec3_sub(c->world[i].translation, before);
}

/* One CCD step at chain joint i; returns the new effector position. need_world: world[i] must
 * be brought up to date (root-first order reads it for the next joint; tip-first order only
 * needs it when limits may have changed the rotation, and rebuilds everything after a sweep). */
static ak_vec3 ccd_step(akp_ik_chain* c, size_t i, ak_vec3 e, float max_step, bool need_world) {
    const ak_joint_type type = akp_ik_type(c, i);
    if (type == AK_JOINT_PRISM) return ak_vec3_add(e, ccd_slide(c, i, e));
    const size_t j = (size_t)c->joints[i];
    const ak_vec3 p = c->world[i].translation;
    if (type != AK_JOINT_HINGE && !c->clamp[i] && max_step >= AK_PI) {
        /* Free and undamped: the shortest arc q = (RE x RD, |RE||RD| + RE.RD) left unnormalised
         * (the local rotation is normalised once after the product), and the effector lands
         * exactly on RD at distance |RE|: p + RD |RE||RD| / |RD|^2. One square root on the
         * sweep's chain from joint to joint. */
        const ak_vec3 re = ak_vec3_sub(e, p), rd = ak_vec3_sub(c->target, p);
        const float rd2 = ak_vec3_length_sq(rd), l2 = ak_vec3_length_sq(re) * rd2;
        if (!(l2 > 1e-24f)) return e;
        const float m = sqrtf(l2), w = m + ak_vec3_dot(re, rd);
        if (w > 1e-6f * m) {
            const ak_vec3 v = ak_vec3_cross(re, rd);
            ak_transform* l = &c->pose[j];
            const ak_quat q = ak_quat_make(v.x, v.y, v.z, w);
            l->rotation = local_after_turn(akp_ik_parent_rot(c, i), q, c->world[i].rotation);
            if (need_world) c->world[i] = akp_ik_compose(akp_ik_parent_world(c, i), *l);
            return ak_vec3_madd(p, rd, m / rd2);
        }
    }
    ak_vec3 axis = ak_vec3_zero();
    if (type == AK_JOINT_HINGE)
        axis = ak_vec3_normalize(ak_quat_rotate(c->world[i].rotation, ak_skeleton_joint_limits(c->skeleton, j).axis));
    ak_quat q = akp_ik_aim_rotation(ak_vec3_sub(e, p), ak_vec3_sub(c->target, p), type == AK_JOINT_HINGE, axis, max_step);
    if (!c->clamp[i]) {
        /* Nothing can clip q: apply it to the local rotation and move the effector by it. */
        ak_transform* l = &c->pose[j];
        const ak_quat parent_rot = akp_ik_parent_rot(c, i);
        l->rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(parent_rot), ak_quat_mul(q, c->world[i].rotation)));
        if (need_world) c->world[i] = akp_ik_compose(akp_ik_parent_world(c, i), *l);
        return ak_vec3_add(p, ak_quat_rotate(q, ak_vec3_sub(e, p)));
    }
    const ak_quat old_rot = c->world[i].rotation;
    akp_ik_rotate(c, i, q);
    /* The rotation really applied, after the limits. */
    ak_quat applied = ak_quat_mul(c->world[i].rotation, ak_quat_conjugate(old_rot));
    return ak_vec3_add(p, ak_quat_rotate(applied, ak_vec3_sub(e, p)));
}

void akp_ik_ccd_sweep(akp_ik_chain* c, float max_step, bool from_root) {
    const size_t last = c->count - 1;
    ak_vec3 e = c->world[last].translation;
    if (from_root) {
        for (size_t i = 0; i < last; ++i) {
            e = ccd_step(c, i, e, max_step, true);
            c->world[i + 1] = akp_ik_compose(c->world[i], c->pose[c->joints[i + 1]]);
        }
    } else {
        for (size_t i = last; i-- > 0;) e = ccd_step(c, i, e, max_step, false);
    }
    akp_ik_fk(c, 0); /* exact positions, no drift from the incremental updates */
}

akp_ik_outcome akp_ik_ccd(akp_ik_chain* c, const ak_ik_chain_job* job) {
    const size_t n = c->count;
    const size_t last = n - 1;
    akp_ik_outcome out = {ak_vec3_distance(c->world[last].translation, c->target), 0};
    float best = out.error;
    int stalled = 0, rebends = 0;
    /* Improvements below this are float noise: further sweeps cannot help. */
    const float noise = 1e-6f * ak_maxf(c->length, 1e-6f);
    while (out.error > c->tolerance && out.iterations < job->max_iterations) {
        akp_ik_ccd_sweep(c, job->max_step, job->ccd_from_root);
        out.error = ak_vec3_distance(c->world[last].translation, c->target);
        ++out.iterations;
        akp_ik_track_best(c, out.error);
        if (out.error < best - noise) {
            best = out.error;
            stalled = 0;
        } else if (++stalled >= 3) {
            /* Stuck straight (a hinge clamped back to straight), or nearly straight and
             * pointing at a target near its line, inside the reach: bend again, a couple of
             * times at most. */
            if (rebends < 2 && akp_ik_unstraighten(c, true)) {
                ++rebends;
                stalled = 0;
                best = out.error = ak_vec3_distance(c->world[last].translation, c->target);
                continue;
            }
            break; /* converged as far as it can (unreachable, or held by limits) */
        }
    }
    out.error = akp_ik_restore_best(c, out.error);
    return out;
}
