/* Damped least squares (Wampler 1986; Buss 2004; Buss & Kim 2005) in its singular value
 * form, with Levenberg-Marquardt adaptation of the damping. With J = sum_i s_i u_i v_i^T:
 *     dq = ClampMaxAbs(sum_i s_i / (s_i^2 + lambda^2) (u_i . e') v_i, pi / 4)
 *     e' = e min(1, (L / 2) / |e_position|)                      (Buss & Kim's target clamp)
 * L the chain length; ClampMaxAbs(w, g) scales w down so that no component exceeds g, a
 * slide counting as an angle of slide / L. Directions with s_i <= 1e-9 max s are dropped,
 * so a rank-deficient J (a planar chain, a straight limb's line) needs no lambda to stay
 * solvable, and the damping acts on each singular direction by its own s_i.
 * J is 3 x dof (position) or 6 x dof (position and orientation, the latter rows weighted to
 * model units). FREE and BALL joints contribute three rotational DOF about the model axes,
 * HINGE joints one about their axis, PRISM joints one slide; a limited hinge at its limit
 * whose step points further out is dropped from J for that step (the clamp would undo its
 * share, and the others would zigzag around the missing motion). The decomposition comes
 * from the eigenvectors of J J^T (3x3 or 6x6, cyclic Jacobi in double: a fixed order, no
 * randomness), v_i = J^T u_i / s_i. A step that lowers the error (in double) is kept and
 * lambda halves (down to 1e-6 L); a step that does not is undone and lambda grows 4x (up
 * to 1e4 L). A straight or nearly straight chain with the target inside its reach sits on
 * a saddle of the error that no Jacobian step leaves (no column along the chain's line,
 * or gains float positions cannot resolve), so it is curled first (akp_ik_unstraighten,
 * target on the line or not), and again, twice at most, if the solve stalls straight. */
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

/* Eigen decomposition of the symmetric m x m matrix a (m <= 6, row stride 6) by cyclic
 * Jacobi rotations: on return a's diagonal holds the eigenvalues and column i of u the unit
 * eigenvector of a[i][i]. Sweeps run in a fixed order until the off-diagonal part is below
 * 1e-30 of the whole (or 64 sweeps), so the result depends on a alone. */
static void jacobi_eigen(double* a, int m, double* u) {
    for (int r = 0; r < m; ++r)
        for (int s = 0; s < m; ++s) u[r * 6 + s] = r == s ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 64; ++sweep) {
        double off = 0.0, all = 0.0;
        for (int p = 0; p < m; ++p) {
            all += a[p * 6 + p] * a[p * 6 + p];
            for (int q = p + 1; q < m; ++q) off += 2.0 * a[p * 6 + q] * a[p * 6 + q];
        }
        if (!(off > 1e-30 * (all + off))) break;
        for (int p = 0; p < m; ++p) {
            for (int q = p + 1; q < m; ++q) {
                const double apq = a[p * 6 + q];
                if (apq == 0.0) continue;
                /* The rotation in the (p, q) plane that zeroes a[p][q]: t = tan of its angle,
                 * the smaller root of t^2 + 2 theta t - 1 = 0. */
                const double theta = (a[q * 6 + q] - a[p * 6 + p]) / (2.0 * apq);
                double t = 1.0 / (fabs(theta) + sqrt(theta * theta + 1.0));
                if (fabs(theta) > 1e150) t = 0.5 / fabs(theta); /* theta^2 would overflow */
                if (theta < 0.0) t = -t;
                const double cs = 1.0 / sqrt(t * t + 1.0), sn = t * cs;
                a[p * 6 + p] -= t * apq;
                a[q * 6 + q] += t * apq;
                a[p * 6 + q] = a[q * 6 + p] = 0.0;
                for (int r = 0; r < m; ++r) {
                    if (r != p && r != q) {
                        const double arp = a[r * 6 + p], arq = a[r * 6 + q];
                        a[r * 6 + p] = a[p * 6 + r] = cs * arp - sn * arq;
                        a[r * 6 + q] = a[q * 6 + r] = sn * arp + cs * arq;
                    }
                    const double urp = u[r * 6 + p], urq = u[r * 6 + q];
                    u[r * 6 + p] = cs * urp - sn * urq;
                    u[r * 6 + q] = sn * urp + cs * urq;
                }
            }
        }
    }
}

/* Largest |x_k| of a step, a slide counted as an angle of slide / length. */
static double max_abs_angle(const double* x, const dls_dof* dofs, size_t m, double inv_len) {
    double big = 0.0;
    for (size_t k = 0; k < m; ++k) big = fmax(big, fabs(x[k]) * (dofs[k].slide ? inv_len : 1.0));
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
 * row-major) and error e, into step[m]. gg: J J^T (rows x rows, stride 6). */
static void damped_step(const float* jac, int rows, size_t m, const double* gg, const float* e, double lambda,
                        const dls_dof* dofs, double inv_len, double* step) {
    const double gamma_max = 0.25 * AK_PI;
    /* Buss & Kim's target clamping: the error counts at most d_max = chain length / 2 in its
     * position part, so a far target pulls along its direction rather than by its distance. */
    const double e_len = sqrt((double)e[0] * e[0] + (double)e[1] * e[1] + (double)e[2] * e[2]);
    const double d_max = 0.5 / inv_len, e_scale = e_len > d_max ? d_max / e_len : 1.0;
    double a[36], u[36];
    memcpy(a, gg, sizeof a);
    jacobi_eigen(a, rows, u);
    double s_max = 0.0;
    for (int i = 0; i < rows; ++i) s_max = fmax(s_max, sqrt(fmax(a[i * 6 + i], 0.0)));
    for (size_t k = 0; k < m; ++k) step[k] = 0.0;
    for (int i = 0; i < rows; ++i) {
        const double s = sqrt(fmax(a[i * 6 + i], 0.0));
        if (!(s > 1e-9 * s_max)) continue; /* below the decomposition's resolution: no direction */
        double alpha = 0.0;
        for (int r = 0; r < rows; ++r) alpha += u[r * 6 + i] * e[r] * e_scale;
        /* v_i = J^T u_i / s_i, times s_i / (s_i^2 + lambda^2) (u_i . e): the 1 / s_i cancels. */
        const double coef = alpha / (s * s + lambda * lambda);
        for (size_t k = 0; k < m; ++k) {
            double acc = 0.0;
            for (int r = 0; r < rows; ++r) acc += (double)jac[r * m + k] * u[r * 6 + i];
            step[k] += acc * coef;
        }
    }
    const double big = max_abs_angle(step, dofs, m, inv_len);
    if (big > gamma_max)
        for (size_t k = 0; k < m; ++k) step[k] *= gamma_max / big;
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
                double acc = 0.0;
                for (size_t k = 0; k < m; ++k) acc += (double)jac[r * m + k] * jac[s * m + k];
                gg[r * 6 + s] = gg[s * 6 + r] = acc;
            }
        for (size_t i = 0; i < n; ++i) saved[i] = c->pose[c->joints[i]];

        /* Try steps with growing damping until one lowers the error (or lambda tops out). */
        bool accepted = false;
        while (!accepted && out.iterations < job->max_iterations) {
            ++out.iterations;
            damped_step(jac, rows, m, gg, e, lambda, dofs, inv_len, step);
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
                damped_step(jac, rows, m, gg, e, lambda, dofs, inv_len, step);
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
