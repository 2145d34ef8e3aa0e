/* Analytic two-bone IK. Everything happens in model space on positions, then the two
 * rotations are moved into the joints' local frames by transforming their axes.
 *
 * Mid joint: it turns by phi about its bend axis n. With u = mid - start, v = end - mid and
 * v = v_par + v_perp about n, the end lands at distance d from the start when
 *     |u + R(phi) v|^2 = d^2  <=>  A cos(phi) + B sin(phi) = K,
 *     A = u.v_perp,  B = u.(n x v_perp),  K = (d^2 - |u|^2 - |v|^2) / 2 - u.v_par,
 * which is the law of cosines written for any axis (for n normal to the bend plane, v_par = 0
 * and it reduces to cos(interior) = (a^2 + b^2 - d^2) / 2ab). Of the two solutions, the one
 * nearer the current bend keeps the knee bending the way it did. Every angle is handled as a
 * (cos, sin) pair and half angles come from sqrt((1 +- cos) / 2), so the solve needs no trig.
 *
 * Start joint: the shortest arc taking start->end onto start->target, then a turn about the
 * start->target axis that puts the mid joint in the half plane of the pole direction. */
#include "ik_internal.h"

static inline ak_vec3 mat_col(const float* m, int c) { return ak_vec3_make(m[c * 4], m[c * 4 + 1], m[c * 4 + 2]); }
static inline ak_vec3 mat_pos(const float* m) { return ak_vec3_make(m[12], m[13], m[14]); }
static inline ak_vec3 mat_rotate(const float* m, ak_vec3 v) {
    return ak_vec3_make(m[0] * v.x + m[4] * v.y + m[8] * v.z, m[1] * v.x + m[5] * v.y + m[9] * v.z,
                        m[2] * v.x + m[6] * v.y + m[10] * v.z);
}
/* Direction of a model-space vector in the joint's local frame (transpose, rescaled). */
static inline ak_vec3 mat_unrotate(const float* m, ak_vec3 v) {
    ak_vec3 r = ak_vec3_make(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                             m[8] * v.x + m[9] * v.y + m[10] * v.z);
    float s2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    if (fabsf(s2 - 1.0f) > 1e-5f && s2 > 0.0f) r = ak_vec3_scale(r, 1.0f / sqrtf(s2)); /* M = sR: R^T v = M^T v / s */
    return r;
}

/* Half-angle quaternion about unit axis from the full angle's (cos, sin), c^2 + s^2 = 1. The
 * larger of cos(a/2), sin(a/2) comes from a square root and the other from
 * sin(a) = 2 sin(a/2) cos(a/2), so small angles keep their precision (sqrt(1 - c) alone
 * would quantise them to ~3e-4 rad in float). */
static inline ak_quat half_angle(ak_vec3 axis, float c, float s) {
    float ch, sh;
    if (c >= 0.0f) {
        ch = sqrtf(0.5f + 0.5f * c);
        sh = 0.5f * s / ch;
    } else {
        sh = sqrtf(ak_maxf(0.5f - 0.5f * c, 0.0f));
        if (s < 0.0f) sh = -sh;
        ch = 0.5f * s / sh;
    }
    return ak_quat_make(axis.x * sh, axis.y * sh, axis.z * sh, ch);
}

static inline ak_quat weight_toward_identity(ak_quat q, float keep) {
    if (keep <= 0.0f) return q;
    return ak_quat_nlerp(ak_quat_identity(), q, 1.0f - keep);
}

bool akp_ik_two_bone_solve(const ak_ik_two_bone_job* job, int branch, ak_quat* out_start, ak_quat* out_mid) {
    const float *S = job->start.m, *M = job->mid.m, *E = job->end.m;
    const ak_vec3 s = mat_pos(S), m = mat_pos(M), e = mat_pos(E);
    const ak_vec3 u = ak_vec3_sub(m, s), v = ak_vec3_sub(e, m), st = ak_vec3_sub(job->target, s);
    const float a2 = ak_vec3_dot(u, u), b2 = ak_vec3_dot(v, v), d2 = ak_vec3_dot(st, st);
    const float a = sqrtf(a2), b = sqrtf(b2), d = sqrtf(d2);

    /* Reach: softened, then clamped to what the two bones can span. */
    const float lmax = a + b, lmin = fabsf(a - b);
    bool reached = d <= lmax * (1.0f + 1e-6f) && d >= lmin - 1e-6f * lmax;
    float dd = d;
    if (job->soft > 0.0f) {
        const float ds = (1.0f - job->soft) * lmax, band = lmax - ds;
        if (d > ds && band > 0.0f) {
            dd = ds + band * (1.0f - expf((ds - d) / band));
            reached = false;
        }
    }
    dd = ak_clampf(dd, lmin, lmax);

    /* Bend axis in model space. */
    ak_vec3 n, n_local;
    const bool axis_given = job->mid_axis.x != 0.0f || job->mid_axis.y != 0.0f || job->mid_axis.z != 0.0f;
    if (axis_given) {
        n_local = ak_vec3_normalize(job->mid_axis);
        n = ak_vec3_normalize(mat_rotate(M, n_local));
    } else {
        n = ak_vec3_cross(u, v);
        float n2 = ak_vec3_dot(n, n);
        if (n2 > 1e-12f * a2 * b2) {
            n = ak_vec3_scale(n, 1.0f / sqrtf(n2));
        } else { /* straight (or zero) bones: any axis normal to the limb, the pole's if any */
            n = ak_vec3_normalize(ak_vec3_cross(u, job->pole));
            if (ak_vec3_dot(n, n) == 0.0f) n = ak_vec3_any_perpendicular(a2 > 0.0f ? u : v);
        }
        n_local = ak_vec3_normalize(mat_unrotate(M, n));
    }

    /* Mid joint: A cos(phi) + B sin(phi) = K. */
    const float vn = ak_vec3_dot(n, v);
    const ak_vec3 v_perp = ak_vec3_madd(v, n, -vn);
    const ak_vec3 n_x_vp = ak_vec3_cross(n, v_perp);
    const float A = ak_vec3_dot(u, v_perp), B = ak_vec3_dot(u, n_x_vp);
    const float K = 0.5f * (dd * dd - a2 - b2) - vn * ak_vec3_dot(u, n);
    const float r2 = A * A + B * B;
    float cphi = 1.0f, sphi = 0.0f;
    if (r2 > 1e-24f * (a2 * b2 + 1e-30f)) {
        const float inv = 1.0f / sqrtf(r2);
        const float ca = A * inv, sa = B * inv;
        const float c = ak_clampf(K * inv, -1.0f, 1.0f), sn = sqrtf(1.0f - c * c);
        const float c1 = ca * c - sa * sn, s1 = sa * c + ca * sn; /* phi = alpha + beta */
        const float c2 = ca * c + sa * sn, s2 = sa * c - ca * sn; /* phi = alpha - beta */
        if ((c1 >= c2) != (branch != 0)) cphi = c1, sphi = s1;
        else cphi = c2, sphi = s2;
    }
    ak_quat q_mid = half_angle(n_local, cphi, sphi);

    /* Start joint: aim start->end at the target, then turn the plane towards the pole. */
    ak_quat q_start = ak_quat_identity();
    if (d2 > 1e-24f) {
        const ak_vec3 v_rot = ak_vec3_add(ak_vec3_madd(ak_vec3_scale(n, vn), v_perp, cphi), ak_vec3_scale(n_x_vp, sphi));
        const ak_vec3 f = ak_vec3_add(u, v_rot);
        const float f2 = ak_vec3_dot(f, f);
        if (f2 > 1e-24f) {
            const ak_vec3 cr = ak_vec3_cross(f, st);
            const float w = sqrtf(f2 * d2) + ak_vec3_dot(f, st);
            if (w > 1e-6f * sqrtf(f2 * d2)) {
                q_start = ak_quat_normalize(ak_quat_make(cr.x, cr.y, cr.z, w));
            } else { /* opposite: half a turn about an axis normal to the limb, n if possible */
                ak_vec3 ax = ak_vec3_dot(n, f) * ak_vec3_dot(n, f) < 1e-6f * f2 ? n : ak_vec3_any_perpendicular(f);
                q_start = ak_quat_make(ax.x, ax.y, ax.z, 0.0f);
            }
        }
        const ak_vec3 k = ak_vec3_scale(st, 1.0f / d);
        const bool has_pole = job->pole.x != 0.0f || job->pole.y != 0.0f || job->pole.z != 0.0f;
        if (has_pole) {
            const ak_vec3 m1 = ak_quat_rotate(q_start, u);
            const ak_vec3 mp = ak_vec3_madd(m1, k, -ak_vec3_dot(k, m1));
            const ak_vec3 pp = ak_vec3_madd(job->pole, k, -ak_vec3_dot(k, job->pole));
            const float c = ak_vec3_dot(mp, pp), sn = ak_vec3_dot(k, ak_vec3_cross(mp, pp));
            const float r = sqrtf(c * c + sn * sn);
            if (r > 1e-20f) q_start = ak_quat_mul(half_angle(k, c / r, sn / r), q_start);
        }
        if (job->twist != 0.0f) q_start = ak_quat_mul(ak_quat_from_axis_angle(k, job->twist), q_start);
    }
    /* Into the start joint's local frame: same angle, axis seen from the joint. */
    ak_vec3 axis_local = mat_unrotate(S, ak_vec3_make(q_start.x, q_start.y, q_start.z));
    q_start = ak_quat_make(axis_local.x, axis_local.y, axis_local.z, q_start.w);

    *out_start = weight_toward_identity(q_start, job->keep_animation);
    *out_mid = weight_toward_identity(q_mid, job->keep_animation);
    return reached;
}

/* 0 when every element of the 16 floats is finite: x * 0 is 0 for finite x, NaN otherwise. */
static inline float nonfinite16(const float* m) {
    float acc = 0.0f;
    for (int i = 0; i < 16; ++i) acc += m[i] * 0.0f;
    return acc;
}

ak_result ak_ik_two_bone_validate(const ak_ik_two_bone_job* job) {
    if (!job || !job->out_start_rot || !job->out_mid_rot) return AK_ERR_NULL_ARG;
    float bad = nonfinite16(job->start.m) + nonfinite16(job->mid.m) + nonfinite16(job->end.m);
    if (bad != 0.0f || !ak_vec3_is_finite(job->target) || !ak_vec3_is_finite(job->pole) ||
        !ak_vec3_is_finite(job->mid_axis) || !ak_finitef(job->twist))
        return AK_ERR_BAD_DATA;
    if (!(job->soft >= 0.0f && job->soft < 1.0f)) return AK_ERR_BAD_ARG;
    if (!(job->keep_animation >= 0.0f && job->keep_animation <= 1.0f)) return AK_ERR_BAD_ARG;
    return AK_OK;
}

ak_result ak_ik_two_bone_run(const ak_ik_two_bone_job* job) {
    ak_result r = ak_ik_two_bone_validate(job);
    if (r != AK_OK) return r;
    bool reached = akp_ik_two_bone_solve(job, 0, job->out_start_rot, job->out_mid_rot);
    if (job->out_reached) *job->out_reached = reached;
    return AK_OK;
}

/* The chain job's TWO_BONE solver: the same core on the chain's model transforms, then the
 * limits. A hinge mid joint bends about its own axis; if its limits reject the bend nearer the
 * current one, the other bend is tried and the one ending closer to the target kept. */
void akp_ik_two_bone_chain(akp_ik_chain* c, const ak_ik_chain_job* job) {
    ak_ik_two_bone_job tb = {
        .start = ak_transform_to_mat4(c->world[0]),
        .mid = ak_transform_to_mat4(c->world[1]),
        .end = ak_transform_to_mat4(c->world[2]),
        .target = c->target,
        .pole = job->pole,
        .soft = job->soft,
        .keep_animation = job->keep_animation,
    };
    const size_t j0 = (size_t)c->joints[0], j1 = (size_t)c->joints[1];
    const ak_joint_type mid_type = akp_ik_type(c, 1);
    if (mid_type == AK_JOINT_HINGE) tb.mid_axis = ak_skeleton_joint_limits(c->skeleton, j1).axis;
    const ak_transform l0 = c->pose[j0], l1 = c->pose[j1];
    float best_err = -1.0f;
    ak_transform best0 = l0, best1 = l1;
    for (int branch = 0; branch < 2; ++branch) {
        ak_quat qs, qm;
        akp_ik_two_bone_solve(&tb, branch, &qs, &qm);
        ak_transform n0 = l0, n1 = l1;
        n0.rotation = ak_quat_normalize(ak_quat_mul(l0.rotation, qs));
        n1.rotation = ak_quat_normalize(ak_quat_mul(l1.rotation, qm));
        bool clamped = false;
        if (c->limits) {
            ak_transform k0 = ak_skeleton_limit_joint(c->skeleton, j0, n0);
            ak_transform k1 = ak_skeleton_limit_joint(c->skeleton, j1, n1);
            clamped = akp_quat_angle(ak_quat_mul(ak_quat_conjugate(k1.rotation), n1.rotation)) > 1e-4f ||
                      akp_quat_angle(ak_quat_mul(ak_quat_conjugate(k0.rotation), n0.rotation)) > 1e-4f;
            n0 = k0, n1 = k1;
        }
        c->pose[j0] = n0, c->pose[j1] = n1;
        akp_ik_fk(c, 0);
        float err = ak_vec3_distance(c->world[2].translation, c->target);
        if (best_err < 0.0f || err < best_err) best_err = err, best0 = n0, best1 = n1;
        if (!clamped) break;
    }
    c->pose[j0] = best0, c->pose[j1] = best1;
    akp_ik_fk(c, 0);
}
