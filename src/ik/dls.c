/* Damped least squares (Wampler 1986; Buss 2004) with Levenberg-Marquardt adaptive damping
 * and Buss & Kim's (2005) clamps:
 *     dq = ClampMaxAbs(J^T (J J^T + lambda^2 I)^-1 e', pi / 4)
 *     e' = e min(1, (L / 2) / |e_position|)                       (the target clamp)
 * L the chain length; ClampMaxAbs(w, g) scales w down so that no component exceeds g (Buss
 * & Kim's gamma_max), a slide counting as an angle of slide / L. In singular values,
 * J = sum_i s_i u_i v_i^T, the step is sum_i s_i / (s_i^2 + lambda^2) (u_i . e') v_i: lambda
 * damps only the directions with s_i near or below it, the ones a (nearly) singular J
 * resolves badly. lambda adapts to the error: a step that lowers it (compared in double) is
 * kept and lambda halves, down to 1e-6 L; a step that does not is undone and lambda grows
 * 4x, up to 1e4 L. The 3x3 or 6x6 system is solved by Cholesky in double, so it stays
 * positive definite for lambda down to 1e-6 L even where J is rank deficient. (Buss & Kim's
 * selective damping, a clamp per singular direction, was tried in this accept/reject loop:
 * about 5x the iterations from nearly straight limbs and 2.5-3.4x at the 99th percentile
 * of bench_ik's random targets; it pointed a straight arm at a target behind it more
 * exactly, but with the whole budget of 50 iterations.)
 * J is 3 x dof (position) or 6 x dof (position and orientation, the latter rows weighted to
 * model units). FREE and BALL joints contribute three rotational DOF about the model axes,
 * HINGE joints one about their axis, PRISM joints one slide; a limited hinge at its limit
 * whose step points further out is dropped from J for that step (the clamp would undo its
 * share, and the others would zigzag around the missing motion).
 * A straight or nearly straight chain with the target inside its reach sits on a saddle of
 * the error that no Jacobian step leaves (J has no column along the chain's line, or the
 * gains are below what float positions resolve), so it is curled first
 * (akp_ik_unstraighten, target on the line or not), and again, twice at most, if the solve
 * stalls straight. */
#include <string.h>

#include "ik_internal.h"

typedef struct dls_dof {
    ak_vec3 axis;  /* model space: rotation axis, or slide direction per parent unit */
    int32_t joint; /* chain index */
    int32_t slide; /* 1 for a prism slide */
} dls_dof;

size_t akp_ik_dls_scratch_size(size_t n) {
    return akp_align16(n * sizeof(ak_transform)) + /* saved locals */
           akp_align16(3 * n * sizeof(dls_dof)) +  /* dofs */
           akp_align16(6 * 3 * n * sizeof(float)) + /* jacobian */
           akp_align16(3 * n * sizeof(double));     /* step */
}

/* Solve the symmetric positive definite system A x = b (size m <= 6, row stride 6) by
 * Cholesky, in double; false when A is not positive definite in double. */
static bool cholesky_solve(double* a, int m, const double* b, double* x) {
    for (int j = 0; j < m; ++j) {
        double d = a[j * 6 + j];
        for (int k = 0; k < j; ++k) d -= a[j * 6 + k] * a[j * 6 + k];
        if (!(d > 0.0)) return false;
        d = sqrt(d);
        a[j * 6 + j] = d;
        for (int i = j + 1; i < m; ++i) {
            double s = a[i * 6 + j];
            for (int k = 0; k < j; ++k) s -= a[i * 6 + k] * a[j * 6 + k];
            a[i * 6 + j] = s / d;
        }
    }
    double y[6];
    for (int i = 0; i < m; ++i) {
        double s = b[i];
        for (int k = 0; k < i; ++k) s -= a[i * 6 + k] * y[k];
        y[i] = s / a[i * 6 + i];
    }
    for (int i = m; i-- > 0;) {
        double s = y[i];
        for (int k = i + 1; k < m; ++k) s -= a[k * 6 + i] * x[k];
        x[i] = s / a[i * 6 + i];
    }
    return true;
}

/* Largest |x_k| of a step, a slide counted as an angle of slide / length. */
static double max_abs_angle(const double* x, const dls_dof* dofs, size_t m, double inv_len) {
    double big = 0.0;
    for (size_t k = 0; k < m; ++k) {
        const double a = fabs(x[k]) * (dofs[k].slide ? inv_len : 1.0);
        big = a > big ? a : big; /* not fmax: a libm call per DOF */
    }
    return big;
}

/* Error vector (3 or 6 rows) and its squared norm (in double, so that the small gains near
 * a singular pose are not rounded away). */
static double dls_error(const akp_ik_chain* c, const ak_quat* target_rot, float w, float* e) {
    const ak_transform eff = c->world[c->count - 1];
    ak_vec3 d = ak_vec3_sub(c->target, eff.translation);
    e[0] = d.x, e[1] = d.y, e[2] = d.z;
    double sq = (double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z;
    if (target_rot) {
        ak_vec3 r = ak_vec3_scale(akp_quat_to_rotvec(ak_quat_mul(*target_rot, ak_quat_conjugate(eff.rotation))), w);
        e[3] = r.x, e[4] = r.y, e[5] = r.z;
        sq += (double)r.x * r.x + (double)r.y * r.y + (double)r.z * r.z;
    }
    return sq;
}

/* The damped step (the formulas at the top of the file) for the Jacobian jac (rows x m,
 * row-major) and error e, into step[m]; false when J J^T + lambda^2 I is not positive
 * definite in double. gg: J J^T (rows x rows, stride 6). */
static bool damped_step(const float* jac, int rows, size_t m, const double* gg, const float* e, double lambda,
                        const dls_dof* dofs, double inv_len, double* step) {
    const double gamma_max = 0.25 * AK_PI;
    /* Buss & Kim's target clamping: the error counts at most d_max = chain length / 2 in its
     * position part, so a far target pulls along its direction rather than by its distance. */
    const double e_len = sqrt((double)e[0] * e[0] + (double)e[1] * e[1] + (double)e[2] * e[2]);
    const double d_max = 0.5 / inv_len, e_scale = e_len > d_max ? d_max / e_len : 1.0;
    double a[36], b[6], y[6];
    memcpy(a, gg, sizeof a);
    for (int r = 0; r < rows; ++r) {
        a[r * 6 + r] += lambda * lambda;
        b[r] = e[r] * e_scale;
    }
    if (!cholesky_solve(a, rows, b, y)) return false;
    for (size_t k = 0; k < m; ++k) {
        double acc = 0.0;
        for (int r = 0; r < rows; ++r) acc += (double)jac[r * m + k] * y[r];
        step[k] = acc;
    }
    const double big = max_abs_angle(step, dofs, m, inv_len);
    if (big > gamma_max)
        for (size_t k = 0; k < m; ++k) step[k] *= gamma_max / big;
    return true;
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
    double* step = (double*)mem;

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
    const double inv_len = 1.0 / len;
    float lambda = job->dls_damping;
    const float lambda_min = 1e-6f * len, lambda_max = 1e4f * len;
    const float angle_tol_w = job->angle_tolerance * w;

    /* The saddle: a straight chain and a target inside its reach, on its line or not. */
    if (ak_vec3_distance(c->world[last].translation, c->target) > c->tolerance) akp_ik_unstraighten(c, true);

    float e[6];
    double err2 = dls_error(c, target_rot, w, e);
    akp_ik_outcome out = {ak_vec3_distance(c->world[last].translation, c->target), 0};
    int stalled = 0, rebends = 0;
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
        double gg[36];
        memset(gg, 0, sizeof gg);
        for (int r = 0; r < rows; ++r)
            for (int s = 0; s <= r; ++s) {
                float acc = 0.0f;
                for (size_t k = 0; k < m; ++k) acc += jac[r * m + k] * jac[s * m + k];
                gg[r * 6 + s] = gg[s * 6 + r] = acc;
            }
        for (size_t i = 0; i < n; ++i) saved[i] = c->pose[c->joints[i]];

        /* Try steps with growing damping until one lowers the error (or lambda tops out). */
        bool accepted = false;
        while (!accepted && out.iterations < job->max_iterations) {
            ++out.iterations;
            if (!damped_step(jac, rows, m, gg, e, lambda, dofs, inv_len, step)) {
                lambda = ak_minf(lambda * 4.0f, lambda_max);
                continue;
            }
            /* A hinge at a limit that the step pushes further cannot follow it (the clamp would
             * undo its part, and the others would zigzag around the missing motion): drop
             * its column and solve again without it. */
            bool pinned = false;
            for (size_t k = 0; k < m; ++k) {
                const size_t i = (size_t)dofs[k].joint, j = (size_t)c->joints[i];
                if (dofs[k].slide || c->types[i] != AK_JOINT_HINGE || !c->clamp[i] || step[k] == 0.0) continue;
                const ak_joint_limits l = ak_skeleton_joint_limits(c->skeleton, j);
                const float a = akp_ik_hinge_angle(c->skeleton, j, c->pose[j].rotation);
                if ((step[k] < 0.0 && a <= l.min + 1e-6f) || (step[k] > 0.0 && a >= l.max - 1e-6f)) {
                    for (int r = 0; r < rows; ++r) jac[(size_t)r * m + k] = 0.0f;
                    pinned = true;
                }
            }
            if (pinned) {
                for (int r = 0; r < rows; ++r)
                    for (int s = 0; s <= r; ++s) {
                        double acc = 0.0;
                        for (size_t k = 0; k < m; ++k) acc += (double)jac[r * m + k] * jac[s * m + k];
                        gg[r * 6 + s] = gg[s * 6 + r] = acc;
                    }
                if (!damped_step(jac, rows, m, gg, e, lambda, dofs, inv_len, step)) {
                    lambda = ak_minf(lambda * 4.0f, lambda_max);
                    continue;
                }
            }
            /* Apply: each joint turns about its axis as measured in the current pose. */
            size_t k = 0;
            for (size_t i = 0; i < moving; ++i) {
                const size_t j = (size_t)c->joints[i];
                ak_transform* l = &c->pose[j];
                const ak_quat parent_rot = akp_ik_parent_rot(c, i); /* world[] still pre-step */
                if (dofs[k].slide) {
                    ak_vec3 axis_p = ak_quat_rotate(ak_skeleton_rest_pose(c->skeleton).ptr[j].rotation,
                                                    ak_skeleton_joint_limits(c->skeleton, j).axis);
                    l->translation = ak_vec3_madd(l->translation, axis_p, (float)step[k]);
                    ++k;
                } else {
                    ak_vec3 rv = ak_vec3_zero();
                    while (k < m && dofs[k].joint == (int32_t)i) {
                        rv = ak_vec3_madd(rv, dofs[k].axis, (float)step[k]);
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
            const double err2_new = dls_error(c, target_rot, w, e_new);
            if (err2_new < err2) {
                accepted = true;
                const double gain = err2 - err2_new;
                memcpy(e, e_new, sizeof e);
                err2 = err2_new;
                lambda = ak_maxf(lambda * 0.5f, lambda_min);
                stalled = gain < 1e-12 * len * len ? stalled + 1 : 0;
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
        if (stalled >= 3 || !accepted) {
            /* Stuck straight with the target inside the reach (a hinge held straight by its
             * limit, or the steps led onto the saddle): curl again, twice at most. With a
             * target rotation the straight pose may be the best trade, so it stays. */
            if (!target_rot && rebends < 2 && out.iterations < job->max_iterations) {
                akp_ik_track_best(c, ak_vec3_distance(c->world[last].translation, c->target));
                if (akp_ik_unstraighten(c, true)) {
                    ++rebends;
                    stalled = 0;
                    lambda = job->dls_damping;
                    err2 = dls_error(c, target_rot, w, e);
                    continue;
                }
            }
            break;
        }
    }
    out.error = ak_vec3_distance(c->world[last].translation, c->target);
    if (!target_rot) {
        akp_ik_track_best(c, out.error);
        out.error = akp_ik_restore_best(c, out.error);
    }
    return out;
}
