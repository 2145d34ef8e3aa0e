/* Damped least squares (Wampler 1986; Buss 2004) with Levenberg-Marquardt adaptive damping:
 *     dq = J^T (J J^T + lambda^2 I)^-1 e
 * J is 3 x dof (position) or 6 x dof (position and orientation, the latter rows weighted to
 * model units). FREE and BALL joints contribute three rotational DOF about the model axes,
 * HINGE joints one about their axis, PRISM joints one slide. A step that lowers the error is
 * kept and lambda shrinks; a step that does not is undone and lambda grows. The system solved
 * is only 3x3 or 6x6, so a step costs O(dof). */
#include <string.h>

#include "ik_internal.h"

typedef struct dls_dof {
    ak_vec3 axis; /* model space: rotation axis, or slide direction per parent unit */
    int32_t joint; /* chain index */
    int32_t slide; /* 1 for a prism slide */
} dls_dof;

size_t akp_ik_dls_scratch_size(size_t n) {
    return akp_align16(n * sizeof(ak_transform)) +     /* saved locals */
           akp_align16(3 * n * sizeof(dls_dof)) +      /* dofs */
           akp_align16(6 * 3 * n * sizeof(float)) +    /* jacobian */
           akp_align16(3 * n * sizeof(float));         /* step */
}

/* Solve the symmetric positive definite system A x = b (size m <= 6) by Cholesky. */
static bool cholesky_solve(float* a, int m, const float* b, float* x) {
    for (int j = 0; j < m; ++j) {
        float d = a[j * 6 + j];
        for (int k = 0; k < j; ++k) d -= a[j * 6 + k] * a[j * 6 + k];
        if (!(d > 0.0f)) return false;
        d = sqrtf(d);
        a[j * 6 + j] = d;
        for (int i = j + 1; i < m; ++i) {
            float s = a[i * 6 + j];
            for (int k = 0; k < j; ++k) s -= a[i * 6 + k] * a[j * 6 + k];
            a[i * 6 + j] = s / d;
        }
    }
    float y[6];
    for (int i = 0; i < m; ++i) {
        float s = b[i];
        for (int k = 0; k < i; ++k) s -= a[i * 6 + k] * y[k];
        y[i] = s / a[i * 6 + i];
    }
    for (int i = m; i-- > 0;) {
        float s = y[i];
        for (int k = i + 1; k < m; ++k) s -= a[k * 6 + i] * x[k];
        x[i] = s / a[i * 6 + i];
    }
    return true;
}

/* Error vector (3 or 6 rows) and its squared norm. */
static float dls_error(const akp_ik_chain* c, const ak_quat* target_rot, float w, float* e) {
    const ak_transform eff = c->world[c->count - 1];
    ak_vec3 d = ak_vec3_sub(c->target, eff.translation);
    e[0] = d.x, e[1] = d.y, e[2] = d.z;
    float sq = ak_vec3_length_sq(d);
    if (target_rot) {
        ak_vec3 r = ak_vec3_scale(akp_quat_to_rotvec(ak_quat_mul(*target_rot, ak_quat_conjugate(eff.rotation))), w);
        e[3] = r.x, e[4] = r.y, e[5] = r.z;
        sq += ak_vec3_length_sq(r);
    }
    return sq;
}

akp_ik_outcome akp_ik_dls(akp_ik_chain* c, const ak_ik_chain_job* job, void* scratch) {
    const size_t n = c->count, last = n - 1;
    unsigned char* mem = (unsigned char*)scratch;
    ak_transform* saved = (ak_transform*)mem;
    mem += akp_align16(n * sizeof(ak_transform));
    dls_dof* dofs = (dls_dof*)mem;
    mem += akp_align16(3 * n * sizeof(dls_dof));
    float* jac = (float*)mem; /* row-major 6 x dof_count, rows of dof_count floats */
    mem += akp_align16(6 * 3 * n * sizeof(float));
    float* step = (float*)mem;

    ak_quat target_rot_v = ak_quat_identity();
    const ak_quat* target_rot = NULL;
    if (job->target_rotation) {
        target_rot_v = ak_quat_normalize(*job->target_rotation);
        target_rot = &target_rot_v;
    }
    const int rows = target_rot ? 6 : 3;
    const float w = job->orientation_weight;
    /* Position only: the effector's own rotation cannot move it, so it has no DOF. */
    const size_t moving = target_rot || akp_ik_type(c, last) == AK_JOINT_PRISM ? n : last;
    const float len = ak_maxf(c->length, 1e-6f);
    float lambda = job->dls_damping;
    const float lambda_min = 1e-6f * len, lambda_max = 1e4f * len;
    const float angle_tol_w = job->angle_tolerance * w;

    float e[6];
    float err2 = dls_error(c, target_rot, w, e);
    akp_ik_outcome out = {ak_vec3_distance(c->world[last].translation, c->target), 0};
    int stalled = 0;
    while (out.iterations < job->max_iterations) {
        const float pos_err = sqrtf(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        float ang_err = 0.0f;
        if (target_rot) ang_err = sqrtf(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]);
        if (pos_err <= c->tolerance && (!target_rot || ang_err <= angle_tol_w)) break;

        /* Degrees of freedom and Jacobian columns at the current pose. */
        size_t m = 0;
        const ak_vec3 pe = c->world[last].translation;
        for (size_t i = 0; i < moving; ++i) {
            const ak_joint_type type = akp_ik_type(c, i);
            const size_t j = (size_t)c->joints[i];
            if (type == AK_JOINT_PRISM) {
                const ak_transform parent = akp_ik_parent_world(c, i);
                ak_vec3 axis_p = ak_quat_rotate(ak_skeleton_rest_pose(c->skeleton).ptr[j].rotation,
                                                ak_skeleton_joint_limits(c->skeleton, j).axis);
                dofs[m].axis = ak_quat_rotate(parent.rotation, ak_vec3_mul(parent.scale, axis_p));
                dofs[m].joint = (int32_t)i, dofs[m].slide = 1, ++m;
            } else if (type == AK_JOINT_HINGE) {
                dofs[m].axis = ak_vec3_normalize(
                    ak_quat_rotate(c->world[i].rotation, ak_skeleton_joint_limits(c->skeleton, j).axis));
                dofs[m].joint = (int32_t)i, dofs[m].slide = 0, ++m;
            } else {
                for (int a = 0; a < 3; ++a) {
                    dofs[m].axis = ak_vec3_make(a == 0, a == 1, a == 2);
                    dofs[m].joint = (int32_t)i, dofs[m].slide = 0, ++m;
                }
            }
        }
        for (size_t k = 0; k < m; ++k) {
            ak_vec3 lin, ang;
            if (dofs[k].slide) {
                lin = dofs[k].axis;
                ang = ak_vec3_zero();
            } else {
                lin = ak_vec3_cross(dofs[k].axis, ak_vec3_sub(pe, c->world[dofs[k].joint].translation));
                ang = ak_vec3_scale(dofs[k].axis, w);
            }
            jac[0 * m + k] = lin.x, jac[1 * m + k] = lin.y, jac[2 * m + k] = lin.z;
            if (rows == 6) jac[3 * m + k] = ang.x, jac[4 * m + k] = ang.y, jac[5 * m + k] = ang.z;
        }
        float jjt[36];
        for (int r = 0; r < rows; ++r)
            for (int s = 0; s <= r; ++s) {
                float acc = 0.0f;
                for (size_t k = 0; k < m; ++k) acc += jac[r * m + k] * jac[s * m + k];
                jjt[r * 6 + s] = jjt[s * 6 + r] = acc;
            }
        for (size_t i = 0; i < n; ++i) saved[i] = c->pose[c->joints[i]];

        /* Try steps with growing damping until one lowers the error (or lambda tops out). */
        bool accepted = false;
        while (!accepted && out.iterations < job->max_iterations) {
            float a[36], y[6];
            memcpy(a, jjt, sizeof a);
            for (int r = 0; r < rows; ++r) a[r * 6 + r] += lambda * lambda;
            ++out.iterations;
            if (!cholesky_solve(a, rows, e, y)) {
                lambda = ak_minf(lambda * 4.0f, lambda_max);
                continue;
            }
            float biggest = 0.0f;
            for (size_t k = 0; k < m; ++k) {
                float s = 0.0f;
                for (int r = 0; r < rows; ++r) s += jac[r * m + k] * y[r];
                step[k] = s;
                if (!dofs[k].slide) biggest = ak_maxf(biggest, fabsf(s));
            }
            /* Keep each rotation in the range where the linearisation means something. */
            const float scale = biggest > 0.5f ? 0.5f / biggest : 1.0f;
            /* Apply: each joint turns about its axis as measured in the current pose. */
            size_t k = 0;
            for (size_t i = 0; i < moving; ++i) {
                const size_t j = (size_t)c->joints[i];
                ak_transform* l = &c->pose[j];
                const ak_quat parent_rot = akp_ik_parent_rot(c, i); /* world[] still pre-step */
                if (dofs[k].slide) {
                    ak_vec3 axis_p = ak_quat_rotate(ak_skeleton_rest_pose(c->skeleton).ptr[j].rotation,
                                                    ak_skeleton_joint_limits(c->skeleton, j).axis);
                    l->translation = ak_vec3_madd(l->translation, axis_p, step[k] * scale);
                    ++k;
                } else {
                    ak_vec3 rv = ak_vec3_zero();
                    while (k < m && dofs[k].joint == (int32_t)i) {
                        rv = ak_vec3_madd(rv, dofs[k].axis, step[k] * scale);
                        ++k;
                    }
                    ak_quat q = akp_quat_from_rotvec(rv);
                    ak_quat local_q = ak_quat_mul(ak_quat_conjugate(parent_rot), ak_quat_mul(q, parent_rot));
                    l->rotation = ak_quat_normalize(ak_quat_mul(local_q, l->rotation));
                }
                if (c->types[i] != AK_JOINT_FREE) *l = akp_ik_limit(c->skeleton, j, *l);
            }
            /* world[] stayed pre-step while the joints were set (the axes were measured there). */
            akp_ik_fk(c, 0);
            float e_new[6];
            float err2_new = dls_error(c, target_rot, w, e_new);
            if (err2_new < err2) {
                accepted = true;
                const float gain = err2 - err2_new;
                memcpy(e, e_new, sizeof e);
                err2 = err2_new;
                lambda = ak_maxf(lambda * 0.5f, lambda_min);
                stalled = gain < 1e-12f * len * len ? stalled + 1 : 0;
            } else {
                for (size_t i = 0; i < n; ++i) c->pose[c->joints[i]] = saved[i];
                akp_ik_fk(c, 0);
                if (lambda >= lambda_max) {
                    stalled = 3;
                    break;
                }
                lambda = ak_minf(lambda * 4.0f, lambda_max);
            }
        }
        if (stalled >= 3 || !accepted) break;
    }
    out.error = ak_vec3_distance(c->world[last].translation, c->target);
    return out;
}
