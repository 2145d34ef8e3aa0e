/* Tests for the IK module: chains, the four chain solvers, the two-bone job, the FABRIK tree
 * job. Oracles are closed forms (law of cosines, a hand-worked CCD example re-derived in
 * double precision), properties (bone lengths, limits checked with the test's own math,
 * targets made by forward kinematics of random poses so they are reachable) and exact result
 * codes for every validate rule. */
#include <animkit/ik.h>

#include "ak_test.h"

/* ---- helpers ------------------------------------------------------------------------- */

#define MAXJ 40
#define PI_D 3.14159265358979323846

static const ak_ik_solver iterative[3] = {AK_IK_SOLVER_CCD, AK_IK_SOLVER_FABRIK, AK_IK_SOLVER_DLS};
static unsigned char scratch[1 << 16];

typedef struct chain_spec {
    size_t count;        /* joints, root first; the last is the effector */
    float lengths[MAXJ]; /* bone i: from joint i to joint i + 1, along the parent's +x */
    ak_joint_type types[MAXJ];
    ak_joint_limits limits[MAXJ];
} chain_spec;

static ak_skeleton* make_chain(const chain_spec* s) {
    ak_joint_desc j[MAXJ];
    static char names[MAXJ][24];
    memset(j, 0, sizeof j);
    for (size_t i = 0; i < s->count; ++i) {
        snprintf(names[i], sizeof names[i], "j%zu", i);
        j[i].name = names[i];
        j[i].parent = (int)i - 1;
        j[i].rest = ak_transform_identity();
        if (i > 0) j[i].rest.translation = ak_vec3_make(s->lengths[i - 1], 0.0f, 0.0f);
        j[i].type = s->types[i];
        j[i].limits = s->limits[i];
    }
    ak_skeleton_desc d = {.joints = j, .joint_count = s->count};
    ak_skeleton* sk = NULL;
    if (ak_skeleton_create(&d, NULL, &sk, NULL) != AK_OK) return NULL;
    return sk;
}

static void rest_pose(const ak_skeleton* sk, ak_transform* pose) {
    ak_transform_cspan r = ak_skeleton_rest_pose(sk);
    memcpy(pose, r.ptr, r.count * sizeof *pose);
}

static void full_chain(size_t n, int16_t* chain) {
    for (size_t i = 0; i < n; ++i) chain[i] = (int16_t)i;
}

/* Model-space joint positions by the test's own forward kinematics in double precision. */
static void fk_positions(const ak_transform* pose, size_t n, double out[][3]) {
    double rot[4] = {0, 0, 0, 1}, pos[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i) {
        const ak_transform* t = &pose[i];
        double v[3] = {t->translation.x, t->translation.y, t->translation.z};
        /* pos += rot * v */
        double qx = rot[0], qy = rot[1], qz = rot[2], qw = rot[3];
        double tx = 2 * (qy * v[2] - qz * v[1]), ty = 2 * (qz * v[0] - qx * v[2]), tz = 2 * (qx * v[1] - qy * v[0]);
        pos[0] += v[0] + qw * tx + (qy * tz - qz * ty);
        pos[1] += v[1] + qw * ty + (qz * tx - qx * tz);
        pos[2] += v[2] + qw * tz + (qx * ty - qy * tx);
        out[i][0] = pos[0], out[i][1] = pos[1], out[i][2] = pos[2];
        double b[4] = {t->rotation.x, t->rotation.y, t->rotation.z, t->rotation.w};
        double nb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
        for (int k = 0; k < 4; ++k) b[k] /= nb;
        double r[4] = {qw * b[0] + qx * b[3] + qy * b[2] - qz * b[1], qw * b[1] - qx * b[2] + qy * b[3] + qz * b[0],
                       qw * b[2] + qx * b[1] - qy * b[0] + qz * b[3], qw * b[3] - qx * b[0] - qy * b[1] - qz * b[2]};
        memcpy(rot, r, sizeof r);
    }
}

static double dist3(const double* a, const double* b) {
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* Every bone length of the chain matches its rest length within 1e-5 relative. */
static bool lengths_preserved(const chain_spec* s, const ak_transform* pose) {
    double p[MAXJ][3];
    fk_positions(pose, s->count, p);
    for (size_t i = 1; i < s->count; ++i) {
        if (s->types[i] == AK_JOINT_PRISM) continue;
        double l = dist3(p[i], p[i - 1]), want = s->lengths[i - 1];
        if (fabs(l - want) > 1e-5 * fmax(want, 1e-3)) return false;
    }
    return true;
}

static bool pose_finite(const ak_transform* pose, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!ak_transform_is_finite(pose[i])) return false;
    return true;
}

/* The test's own limit check: rel = rest^-1 * local, split about the axis in double. */
static bool within_limits(const chain_spec* s, const ak_skeleton* sk, size_t i, ak_transform local, double tol) {
    ak_transform rest = ak_skeleton_rest_pose(sk).ptr[i];
    ak_quat rel = ak_quat_mul(ak_quat_conjugate(rest.rotation), ak_quat_normalize(local.rotation));
    if (rel.w < 0) rel = ak_quat_neg(rel);
    ak_joint_limits l = s->limits[i];
    double ax[3] = {l.axis.x, l.axis.y, l.axis.z};
    double na = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    if (na == 0) {
        ax[0] = s->types[i] == AK_JOINT_BALL ? 0 : 1, ax[1] = s->types[i] == AK_JOINT_BALL ? 1 : 0, ax[2] = 0, na = 1;
    }
    for (int k = 0; k < 3; ++k) ax[k] /= na;
    double v[3] = {rel.x, rel.y, rel.z};
    double along = v[0] * ax[0] + v[1] * ax[1] + v[2] * ax[2];
    double twist = 2 * atan2(along, rel.w); /* signed twist angle about the axis */
    double tw[4] = {ax[0] * along, ax[1] * along, ax[2] * along, rel.w};
    double ntw = sqrt(tw[0] * tw[0] + tw[1] * tw[1] + tw[2] * tw[2] + tw[3] * tw[3]);
    /* swing = rel * conj(twist / |twist|); its angle by atan2 (acos is ill-conditioned near 0) */
    double swing = 0.0;
    if (ntw > 1e-12) {
        double t[4] = {tw[0] / ntw, tw[1] / ntw, tw[2] / ntw, tw[3] / ntw};
        double r[4] = {rel.x, rel.y, rel.z, rel.w};
        /* r * conj(t) */
        double sw = r[3] * t[3] + r[0] * t[0] + r[1] * t[1] + r[2] * t[2];
        double sx = -r[3] * t[0] + r[0] * t[3] - r[1] * t[2] + r[2] * t[1];
        double sy = -r[3] * t[1] + r[0] * t[2] + r[1] * t[3] - r[2] * t[0];
        double sz = -r[3] * t[2] - r[0] * t[1] + r[1] * t[0] + r[2] * t[3];
        swing = 2 * atan2(sqrt(sx * sx + sy * sy + sz * sz), fabs(sw));
    } else {
        swing = PI_D;
    }
    double dt[3] = {local.translation.x - rest.translation.x, local.translation.y - rest.translation.y,
                    local.translation.z - rest.translation.z};
    switch (s->types[i]) {
    case AK_JOINT_HINGE:
        if (swing > tol) return false;
        if (l.min == 0 && l.max == 0) return true;
        return twist >= l.min - tol && twist <= l.max + tol;
    case AK_JOINT_BALL:
        if (l.cone_angle > 0 && swing > l.cone_angle + tol) return false;
        if (l.twist_min == 0 && l.twist_max == 0) return true;
        return twist >= l.twist_min - tol && twist <= l.twist_max + tol;
    case AK_JOINT_PRISM: {
        if (2 * atan2(sqrt((double)rel.x * rel.x + (double)rel.y * rel.y + (double)rel.z * rel.z), fabs((double)rel.w)) > tol)
            return false;
        ak_vec3 a = ak_quat_rotate(rest.rotation, ak_vec3_normalize(l.axis.x == 0 && l.axis.y == 0 && l.axis.z == 0
                                                                         ? ak_vec3_make(1, 0, 0)
                                                                         : l.axis));
        double d = dt[0] * a.x + dt[1] * a.y + dt[2] * a.z;
        double off = sqrt(fmax(0.0, dt[0] * dt[0] + dt[1] * dt[1] + dt[2] * dt[2] - d * d));
        return off <= tol && d >= l.min - tol && d <= l.max + tol;
    }
    default: return true;
    }
}

/* A random pose inside the limits: random local rotations clamped by the skeleton. */
static void random_pose(const ak_skeleton* sk, ak_rng* rng, ak_transform* pose, bool planar) {
    size_t n = ak_skeleton_joint_count(sk);
    rest_pose(sk, pose);
    for (size_t i = 0; i < n; ++i) {
        ak_vec3 axis = planar ? ak_vec3_make(0, 0, 1)
                              : ak_vec3_make(ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1));
        pose[i].rotation = ak_quat_mul(pose[i].rotation, ak_quat_from_axis_angle(axis, ak_rng_range(rng, -1.2f, 1.2f)));
        if (ak_skeleton_joint_type(sk, i) == AK_JOINT_PRISM)
            pose[i].translation = ak_vec3_add(pose[i].translation, ak_vec3_make(ak_rng_range(rng, -0.3f, 0.3f), 0, 0));
        pose[i] = ak_skeleton_limit_joint(sk, i, pose[i]);
    }
}

static ak_vec3 effector_of(const ak_transform* pose, size_t n) {
    double p[MAXJ][3];
    fk_positions(pose, n, p);
    return ak_vec3_make((float)p[n - 1][0], (float)p[n - 1][1], (float)p[n - 1][2]);
}

static chain_spec uniform_chain(size_t n, ak_joint_type type) {
    chain_spec s;
    memset(&s, 0, sizeof s);
    s.count = n;
    for (size_t i = 0; i < n; ++i) {
        s.lengths[i] = 0.5f + 0.1f * (float)(i % 4);
        s.types[i] = type;
        if (type == AK_JOINT_HINGE) s.limits[i].axis = ak_vec3_make(0, 0, 1);
    }
    return s;
}

typedef struct solve_out {
    ak_result r;
    bool reached;
    float error, angle_error, tolerance;
    size_t iterations;
} solve_out;

static solve_out solve(const ak_skeleton* sk, ak_transform* pose, const int16_t* chain, size_t count,
                       ak_vec3 target, ak_ik_solver solver, const ak_ik_chain_job* extra) {
    ak_ik_chain_job job;
    if (extra) job = *extra;
    else memset(&job, 0, sizeof job);
    solve_out o = {AK_OK, false, -1.0f, -1.0f, 0.0f, 0};
    job.skeleton = sk;
    job.pose = (ak_transform_span){pose, ak_skeleton_joint_count(sk)};
    job.chain = (ak_i16_cspan){chain, count};
    job.target = target;
    job.solver = solver;
    job.scratch = (ak_u8_span)AK_SPAN(scratch);
    job.out_reached = &o.reached;
    job.out_error = &o.error;
    job.out_angle_error = &o.angle_error;
    job.out_iterations = &o.iterations;
    o.tolerance = ak_ik_chain_job_resolved(&job).tolerance;
    o.r = ak_ik_chain_run(&job);
    return o;
}

/* ---- chains --------------------------------------------------------------------------- */

AK_TEST(chain_build) {
    chain_spec s = uniform_chain(5, AK_JOINT_FREE);
    ak_skeleton* sk = make_chain(&s);
    AK_CHECK(sk != NULL);
    if (!sk) return;
    int16_t c[8];
    size_t count = 0;
    AK_CHECK_EQ(ak_ik_chain_build(sk, 1, 4, (ak_i16_span)AK_SPAN(c), &count), AK_OK);
    AK_CHECK_EQ(count, 4);
    AK_CHECK_EQ(c[0], 1);
    AK_CHECK_EQ(c[3], 4);
    AK_CHECK_EQ(ak_ik_chain_build(sk, 2, 2, (ak_i16_span)AK_SPAN(c), &count), AK_OK);
    AK_CHECK_EQ(count, 1);
    AK_CHECK_EQ(ak_ik_chain_build(sk, 3, 1, (ak_i16_span)AK_SPAN(c), &count), AK_ERR_NOT_FOUND);
    AK_CHECK_EQ(ak_ik_chain_build(sk, 0, 5, (ak_i16_span)AK_SPAN(c), &count), AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_ik_chain_build(sk, -1, 2, (ak_i16_span)AK_SPAN(c), &count), AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_ik_chain_build(NULL, 0, 2, (ak_i16_span)AK_SPAN(c), &count), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_ik_chain_build(sk, 0, 4, (ak_i16_span){c, 3}, &count), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(count, 5);

    /* Positions and length against the test's own FK. */
    ak_transform pose[5];
    ak_rng rng = ak_rng_make(7);
    random_pose(sk, &rng, pose, false);
    ak_vec3 pos[5];
    full_chain(5, c);
    AK_CHECK_EQ(ak_ik_chain_positions(sk, (ak_transform_cspan)AK_SPAN(pose), (ak_i16_cspan){c + 1, 4},
                                      (ak_vec3_span)AK_SPAN(pos)),
                AK_OK);
    double ref[5][3];
    fk_positions(pose, 5, ref);
    double len = 0;
    for (int i = 0; i < 4; ++i) {
        AK_CHECK_NEAR(pos[i].x, ref[i + 1][0], 1e-5);
        AK_CHECK_NEAR(pos[i].y, ref[i + 1][1], 1e-5);
        AK_CHECK_NEAR(pos[i].z, ref[i + 1][2], 1e-5);
        len += s.lengths[i];
    }
    AK_CHECK_NEAR(ak_ik_chain_length(sk, (ak_transform_cspan)AK_SPAN(pose), (ak_i16_cspan){c, 5}), len, 1e-5);
    int16_t bad[2] = {0, 2};
    AK_CHECK_EQ(ak_ik_chain_positions(sk, (ak_transform_cspan)AK_SPAN(pose), (ak_i16_cspan)AK_SPAN(bad),
                                      (ak_vec3_span)AK_SPAN(pos)),
                AK_ERR_BAD_HIERARCHY);
    ak_skeleton_destroy(sk);
}

AK_TEST(solver_names) {
    ak_ik_solver s = AK_IK_SOLVER_DEFAULT;
    const char* names[] = {"ccd", "fabrik", "twobone", "dls"};
    for (int i = 0; i < 4; ++i) {
        AK_CHECK_EQ(ak_ik_solver_parse(names[i], &s), AK_OK);
        AK_CHECK_EQ(s, i + 1);
        AK_CHECK_STREQ(ak_ik_solver_name(s), names[i]);
    }
    AK_CHECK_EQ(ak_ik_solver_parse("two-bone", &s), AK_OK);
    AK_CHECK_EQ(s, AK_IK_SOLVER_TWO_BONE);
    AK_CHECK_EQ(ak_ik_solver_parse("newton", &s), AK_ERR_NOT_FOUND);
    AK_CHECK_EQ(ak_ik_solver_parse(NULL, &s), AK_ERR_NULL_ARG);
    AK_CHECK_STREQ(ak_ik_solver_name((ak_ik_solver)99), "");
}

/* ---- validity ------------------------------------------------------------------------- */

AK_TEST(chain_job_validity) {
    chain_spec s = uniform_chain(4, AK_JOINT_FREE);
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    ak_transform pose[4];
    rest_pose(sk, pose);
    int16_t chain[4] = {0, 1, 2, 3};
    ak_ik_chain_job zero;
    memset(&zero, 0, sizeof zero);
    AK_CHECK_EQ(ak_ik_chain_validate(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_ik_chain_run(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_ik_chain_validate(NULL), AK_ERR_NULL_ARG);

    const ak_ik_chain_job good = {
        .skeleton = sk,
        .pose = AK_SPAN(pose),
        .chain = AK_SPAN(chain),
        .target = {1, 1, 0},
        .scratch = AK_SPAN(scratch),
    };
    AK_CHECK_EQ(ak_ik_chain_validate(&good), AK_OK);
    ak_ik_chain_job j;
#define EXPECT(code, mutate)                                                                       \
    do {                                                                                           \
        j = good;                                                                                  \
        mutate;                                                                                    \
        AK_CHECK_EQ(ak_ik_chain_validate(&j), code);                                               \
    } while (0)
    EXPECT(AK_ERR_NULL_ARG, j.skeleton = NULL);
    EXPECT(AK_ERR_NULL_ARG, j.pose.ptr = NULL);
    EXPECT(AK_ERR_NULL_ARG, j.chain.ptr = NULL);
    EXPECT(AK_ERR_NULL_ARG, j.chain.count = 0);
    EXPECT(AK_ERR_SPAN_SMALL, j.pose.count = 3);
    EXPECT(AK_ERR_BAD_ARG, j.solver = AK_IK_SOLVER_COUNT);
    int16_t out_of_range[2] = {0, 4};
    EXPECT(AK_ERR_BAD_INDEX, j.chain = (ak_i16_cspan)AK_SPAN(out_of_range));
    int16_t negative[1] = {-1};
    EXPECT(AK_ERR_BAD_INDEX, j.chain = (ak_i16_cspan)AK_SPAN(negative));
    int16_t skip[3] = {0, 2, 3};
    EXPECT(AK_ERR_BAD_HIERARCHY, j.chain = (ak_i16_cspan)AK_SPAN(skip));
    int16_t reversed[2] = {1, 0};
    EXPECT(AK_ERR_BAD_HIERARCHY, j.chain = (ak_i16_cspan)AK_SPAN(reversed));
    EXPECT(AK_ERR_BAD_ARG, j.solver = AK_IK_SOLVER_TWO_BONE); /* 4 joints */
    EXPECT(AK_OK, (j.solver = AK_IK_SOLVER_TWO_BONE, j.chain.count = 3));
    EXPECT(AK_ERR_BAD_DATA, j.target.y = NAN);
    EXPECT(AK_ERR_BAD_DATA, j.target.z = INFINITY);
    EXPECT(AK_ERR_BAD_DATA, j.pole.x = NAN);
    const ak_quat nan_q = {NAN, 0, 0, 1}, zero_q = {0, 0, 0, 0};
    EXPECT(AK_ERR_BAD_DATA, j.target_rotation = &nan_q);
    EXPECT(AK_ERR_BAD_DATA, j.target_rotation = &zero_q);
    EXPECT(AK_ERR_BAD_ARG, j.tolerance = -1.0f);
    EXPECT(AK_ERR_BAD_ARG, j.tolerance = NAN);
    EXPECT(AK_ERR_BAD_ARG, j.angle_tolerance = -1.0f);
    EXPECT(AK_ERR_BAD_ARG, j.max_step = -0.1f);
    EXPECT(AK_ERR_BAD_ARG, j.dls_damping = -1.0f);
    EXPECT(AK_ERR_BAD_ARG, j.orientation_weight = INFINITY);
    EXPECT(AK_ERR_BAD_ARG, j.soft = 1.0f);
    EXPECT(AK_ERR_BAD_ARG, j.soft = -0.1f);
    EXPECT(AK_ERR_BAD_ARG, j.keep_animation = 1.5f);
    EXPECT(AK_ERR_BAD_ARG, j.keep_animation = -0.5f);
    pose[1].rotation.x = NAN;
    EXPECT(AK_ERR_BAD_DATA, (void)0);
    /* An ancestor outside the chain counts too. */
    int16_t tail[2] = {2, 3};
    EXPECT(AK_ERR_BAD_DATA, j.chain = (ak_i16_cspan)AK_SPAN(tail));
    rest_pose(sk, pose);
    EXPECT(AK_ERR_NULL_ARG, j.scratch.ptr = NULL);
    EXPECT(AK_ERR_SPAN_SMALL, j.scratch.count = ak_ik_chain_scratch_size(AK_IK_SOLVER_FABRIK, 4) - 1);
    EXPECT(AK_OK, j.scratch.count = ak_ik_chain_scratch_size(AK_IK_SOLVER_FABRIK, 4));
    EXPECT(AK_ERR_SPAN_SMALL,
           (j.solver = AK_IK_SOLVER_DLS, j.scratch.count = ak_ik_chain_scratch_size(AK_IK_SOLVER_DLS, 4) - 1));
#undef EXPECT

    /* run writes nothing when validation fails. */
    ak_transform before[4];
    memcpy(before, pose, sizeof pose);
    j = good;
    j.tolerance = -1.0f;
    bool reached = true;
    j.out_reached = &reached;
    AK_CHECK_EQ(ak_ik_chain_run(&j), AK_ERR_BAD_ARG);
    AK_CHECK(memcmp(before, pose, sizeof pose) == 0);
    AK_CHECK(reached == true);

    /* Defaults resolved. */
    ak_ik_chain_job r = ak_ik_chain_job_resolved(&good);
    AK_CHECK_EQ(r.solver, AK_IK_SOLVER_FABRIK);
    AK_CHECK_EQ(r.max_iterations, 50);
    float len = s.lengths[0] + s.lengths[1] + s.lengths[2];
    AK_CHECK_NEAR(r.tolerance, 1e-4f * len, 1e-9);
    AK_CHECK_NEAR(r.max_step, AK_PI, 1e-6);
    AK_CHECK_NEAR(r.angle_tolerance, 1e-3, 1e-9);
    AK_CHECK_NEAR(r.dls_damping, 0.1f * len, 1e-6);
    AK_CHECK_NEAR(r.orientation_weight, len / AK_PI, 1e-6);
    ak_skeleton_destroy(sk);
}

AK_TEST(two_bone_job_validity) {
    ak_quat qs, qm;
    ak_ik_two_bone_job zero;
    memset(&zero, 0, sizeof zero);
    AK_CHECK_EQ(ak_ik_two_bone_validate(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_ik_two_bone_run(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_ik_two_bone_validate(NULL), AK_ERR_NULL_ARG);
    ak_ik_two_bone_job good = {.start = ak_mat4_identity(),
                               .mid = ak_mat4_translation(ak_vec3_make(1, 0, 0)),
                               .end = ak_mat4_translation(ak_vec3_make(2, 0, 0)),
                               .target = {1, 1, 0},
                               .out_start_rot = &qs,
                               .out_mid_rot = &qm};
    AK_CHECK_EQ(ak_ik_two_bone_validate(&good), AK_OK);
    ak_ik_two_bone_job j = good;
    j.out_mid_rot = NULL;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_NULL_ARG);
    j = good, j.out_start_rot = NULL;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_NULL_ARG);
    j = good, j.mid.m[5] = NAN;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_DATA);
    j = good, j.end.m[14] = INFINITY;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_DATA);
    j = good, j.target.x = NAN;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_DATA);
    j = good, j.pole.y = INFINITY;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_DATA);
    j = good, j.mid_axis.z = NAN;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_DATA);
    j = good, j.twist = NAN;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_DATA);
    j = good, j.soft = 1.0f;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_ARG);
    j = good, j.keep_animation = 2.0f;
    AK_CHECK_EQ(ak_ik_two_bone_validate(&j), AK_ERR_BAD_ARG);
    qs = ak_quat_make(9, 9, 9, 9);
    j = good, j.soft = NAN;
    AK_CHECK_EQ(ak_ik_two_bone_run(&j), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(qs.x, 9); /* untouched */
}

/* ---- CCD, step by step ------------------------------------------------------------------- */

/* Planar chain of three unit bones along +x: joints J0 (0,0), J1 (1,0), J2 (2,0), effector E
 * (3,0); target T = (1,2). One CCD sweep, tip to root, each joint turned by
 * atan2(RD) - atan2(RE):
 *   J2: RE = (1,0) -> 0 deg, RD = T - J2 = (-1,2) -> atan2(2,-1) = 116.565 deg: +116.565 deg,
 *       E = J2 + (cos, sin)(116.565 deg) = (1.55279, 0.89443)
 *   J1: RE = E - J1 = (0.55279, 0.89443) -> 58.283 deg, RD = (0,2) -> 90 deg: +31.717 deg,
 *       E = J1 + 1.05146 (cos, sin)(90 deg) = (1, 1.05146)
 *   J0: RE = (1, 1.05146) -> 46.437 deg, RD = (1,2) -> 63.435 deg: +16.998 deg,
 *       E = 1.45141 (cos, sin)(63.435 deg) = (0.64893, 1.29787)
 * Sweep 2 turns J2 by -42.486, J1 by +2.780, J0 by +1.272 deg, E = (0.95497, 1.90993);
 * sweep 3: -4.925, +0.943, +0.444 deg, E = (0.98358, 1.96717).
 * The reference below redoes exactly this with atan2 in double precision. */
static void ccd_planar_reference(int sweeps, double theta[3], double eff[2]) {
    const double T[2] = {1, 2};
    theta[0] = theta[1] = theta[2] = 0;
    for (int s = 0; s < sweeps; ++s) {
        for (int i = 2; i >= 0; --i) {
            double p[4][2] = {{0, 0}}, a = 0;
            for (int k = 0; k < 3; ++k) {
                a += theta[k];
                p[k + 1][0] = p[k][0] + cos(a);
                p[k + 1][1] = p[k][1] + sin(a);
            }
            double d = atan2(T[1] - p[i][1], T[0] - p[i][0]) - atan2(p[3][1] - p[i][1], p[3][0] - p[i][0]);
            while (d > PI_D) d -= 2 * PI_D;
            while (d <= -PI_D) d += 2 * PI_D;
            theta[i] += d;
        }
    }
    double a = 0;
    eff[0] = eff[1] = 0;
    for (int k = 0; k < 3; ++k) {
        a += theta[k];
        eff[0] += cos(a);
        eff[1] += sin(a);
    }
}

static double z_angle(ak_quat q) { return 2.0 * atan2((double)q.z, (double)q.w); }

AK_TEST(ccd_hand_computed_planar) {
    chain_spec s = uniform_chain(4, AK_JOINT_FREE);
    for (int i = 0; i < 3; ++i) s.lengths[i] = 1.0f;
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[4] = {0, 1, 2, 3};
    /* The hand-computed numbers of the comment, as a check on the reference itself. */
    double th[3], e[2];
    ccd_planar_reference(1, th, e);
    AK_CHECK_NEAR(th[2] * 180 / PI_D, 116.565, 1e-3);
    AK_CHECK_NEAR(th[1] * 180 / PI_D, 31.717, 1e-3);
    AK_CHECK_NEAR(th[0] * 180 / PI_D, 16.998, 1e-3);
    AK_CHECK_NEAR(e[0], 0.64893, 1e-5);
    AK_CHECK_NEAR(e[1], 1.29787, 1e-5);
    for (int sweeps = 1; sweeps <= 3; ++sweeps) {
        for (int planar_hinge = 0; planar_hinge < 2; ++planar_hinge) {
            ak_skeleton* use = sk;
            ak_skeleton* hinge_sk = NULL;
            if (planar_hinge) { /* the same chain with z-hinges must take the same steps */
                chain_spec h = s;
                for (int i = 0; i < 4; ++i) h.types[i] = AK_JOINT_HINGE, h.limits[i].axis = ak_vec3_make(0, 0, 1);
                use = hinge_sk = make_chain(&h);
                if (!use) continue;
            }
            ak_transform pose[4];
            rest_pose(use, pose);
            ak_ik_chain_job opts = {.max_iterations = (size_t)sweeps};
            solve_out o = solve(use, pose, chain, 4, ak_vec3_make(1, 2, 0), AK_IK_SOLVER_CCD, &opts);
            ccd_planar_reference(sweeps, th, e);
            AK_CHECK_EQ(o.r, AK_OK);
            AK_CHECK_EQ(o.iterations, sweeps);
            for (int i = 0; i < 3; ++i) {
                double got = z_angle(pose[i].rotation), want = remainder(th[i], 2 * PI_D);
                AK_CHECK_NEAR(got, want, 2e-5);
            }
            ak_vec3 eff = effector_of(pose, 4);
            AK_CHECK_NEAR(eff.x, e[0], 2e-5);
            AK_CHECK_NEAR(eff.y, e[1], 2e-5);
            AK_CHECK_NEAR(eff.z, 0.0, 1e-6);
            AK_CHECK_NEAR(o.error, hypot(1 - e[0], 2 - e[1]), 2e-5);
            AK_CHECK(!o.reached);
            ak_skeleton_destroy(hinge_sk);
        }
    }
    ak_skeleton_destroy(sk);
}

AK_TEST(ccd_options) {
    /* max_step bounds each joint's turn per sweep; root-first order differs from tip-first. */
    chain_spec s = uniform_chain(4, AK_JOINT_FREE);
    for (int i = 0; i < 3; ++i) s.lengths[i] = 1.0f;
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[4] = {0, 1, 2, 3};
    ak_transform pose[4];
    rest_pose(sk, pose);
    ak_ik_chain_job opts = {.max_iterations = 1, .max_step = 0.1f};
    solve_out o = solve(sk, pose, chain, 4, ak_vec3_make(1, 2, 0), AK_IK_SOLVER_CCD, &opts);
    AK_CHECK_EQ(o.iterations, 1);
    for (int i = 0; i < 3; ++i) AK_CHECK_NEAR(fabs(z_angle(pose[i].rotation)), 0.1, 1e-5);

    /* Root first: J0 turns first, by atan2(2,1) - 0 = 63.435 deg (RE = (3,0), RD = (1,2)). */
    rest_pose(sk, pose);
    ak_ik_chain_job root_first = {.max_iterations = 1, .ccd_from_root = true};
    o = solve(sk, pose, chain, 4, ak_vec3_make(1, 2, 0), AK_IK_SOLVER_CCD, &root_first);
    AK_CHECK_NEAR(z_angle(pose[0].rotation), atan2(2.0, 1.0), 1e-5);
    /* Many sweeps from the root converge too. */
    /* A straight chain pointing through the target is a fixed point of root-first CCD (every
     * RE is parallel to its RD), so this run starts bent. */
    rest_pose(sk, pose);
    pose[1].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.3f);
    root_first.max_iterations = 200;
    o = solve(sk, pose, chain, 4, ak_vec3_make(1, 2, 0), AK_IK_SOLVER_CCD, &root_first);
    AK_CHECK(o.reached);
    ak_skeleton_destroy(sk);
}

/* ---- reachable targets ------------------------------------------------------------------ */

static void reach_random_targets(const chain_spec* s, bool planar, ak_ik_solver solver, int trials, int min_ok,
                                 size_t max_iterations, float rel_tolerance) {
    ak_skeleton* sk = make_chain(s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[MAXJ];
    full_chain(s->count, chain);
    ak_rng rng = ak_rng_make(1234 + (uint64_t)solver);
    int ok = 0;
    double len = 0;
    for (size_t i = 0; i + 1 < s->count; ++i) len += s->lengths[i];
    for (int t = 0; t < trials; ++t) {
        ak_transform goal[MAXJ], pose[MAXJ];
        random_pose(sk, &rng, goal, planar);
        ak_vec3 target = effector_of(goal, s->count);
        random_pose(sk, &rng, pose, planar);
        ak_ik_chain_job opts = {.max_iterations = max_iterations, .tolerance = rel_tolerance * (float)len};
        solve_out o = solve(sk, pose, chain, s->count, target, solver, &opts);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(pose_finite(pose, s->count));
        AK_CHECK_MSG(lengths_preserved(s, pose), "%s trial %d: bone lengths changed", ak_ik_solver_name(solver), t);
        for (size_t i = 0; i < s->count; ++i)
            AK_CHECK_MSG(within_limits(s, sk, i, pose[i], 1e-4), "%s trial %d: joint %zu outside its limits",
                         ak_ik_solver_name(solver), t, i);
        /* reported error is the true distance */
        ak_vec3 eff = effector_of(pose, s->count);
        AK_CHECK_NEAR(o.error, ak_vec3_distance(eff, target), 1e-5 * len + 1e-6);
        if (o.reached) {
            AK_CHECK(o.error <= o.tolerance);
            ++ok;
        } else if (getenv("IKDBG")) {
            printf("%s miss: err %g (tol %g) iters %zu\n", ak_ik_solver_name(solver), o.error, o.tolerance, o.iterations);
        }
    }
    if (getenv("IKDBG")) printf("COUNT %s %d/%d (need %d)\n", ak_ik_solver_name(solver), ok, trials, min_ok);
    AK_CHECK_MSG(ok >= min_ok, "%s: %d of %d reached (need %d)", ak_ik_solver_name(solver), ok, trials, min_ok);
    ak_skeleton_destroy(sk);
}

AK_TEST(reach_free_3d) {
    chain_spec s = uniform_chain(6, AK_JOINT_FREE);
    /* CCD's tail is slow (it moves one joint at a time), so it gets a looser tolerance. */
    /* An independent planar CCD in double precision (atan2 steps, 4 bones, same angle
     * ranges) misses about 7% of such targets within 200 sweeps: the classic slow tail when
     * the target lies near the base. */
    reach_random_targets(&s, false, AK_IK_SOLVER_CCD, 100, 90, 200, 1e-3f);
    reach_random_targets(&s, false, AK_IK_SOLVER_FABRIK, 100, 95, 50, 1e-4f); /* slow tail, see BENCHMARKS.md */
    reach_random_targets(&s, false, AK_IK_SOLVER_DLS, 100, 99, 50, 1e-4f);
}

AK_TEST(reach_planar_hinges) {
    chain_spec s = uniform_chain(5, AK_JOINT_HINGE);
    reach_random_targets(&s, true, AK_IK_SOLVER_CCD, 100, 90, 200, 1e-3f);
    reach_random_targets(&s, true, AK_IK_SOLVER_FABRIK, 100, 95, 100, 1e-4f);
    reach_random_targets(&s, true, AK_IK_SOLVER_DLS, 100, 98, 50, 1e-4f);
}

AK_TEST(limits_never_violated) {
    /* A mixed chain: limited hinges, cone/twist balls, a prism. Targets from random poses
     * inside the limits; every joint checked after every solve (inside the helper). The
     * success bar is lower: limits make the problem hard for position-based solvers. */
    chain_spec s = uniform_chain(7, AK_JOINT_BALL);
    s.types[1] = AK_JOINT_HINGE, s.limits[1].axis = ak_vec3_make(0, 0, 1), s.limits[1].min = -0.2f,
    s.limits[1].max = 1.5f;
    s.limits[2].cone_angle = 0.6f, s.limits[2].axis = ak_vec3_make(1, 0, 0), s.limits[2].twist_min = -0.3f,
    s.limits[2].twist_max = 0.3f;
    s.types[3] = AK_JOINT_PRISM, s.limits[3].axis = ak_vec3_make(1, 0, 0), s.limits[3].min = -0.2f,
    s.limits[3].max = 0.2f;
    s.types[4] = AK_JOINT_HINGE, s.limits[4].axis = ak_vec3_make(0, 1, 0), s.limits[4].min = 0.0f,
    s.limits[4].max = 2.0f;
    s.limits[5].cone_angle = 0.8f, s.limits[5].axis = ak_vec3_make(1, 0, 0);
    for (int k = 0; k < 3; ++k) reach_random_targets(&s, false, iterative[k], 60, k == 2 ? 54 : 45, 100, 1e-3f);
}

AK_TEST(animated_translation_kept) {
    /* An animated pose may move a hinge joint off its rest offset; the solvers change only
     * rotations, so that (longer) bone stays as the animation made it. */
    chain_spec s = uniform_chain(4, AK_JOINT_HINGE);
    s.limits[1].min = -1.0f, s.limits[1].max = 1.0f;
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[4] = {0, 1, 2, 3};
    const ak_ik_solver all[4] = {AK_IK_SOLVER_CCD, AK_IK_SOLVER_FABRIK, AK_IK_SOLVER_DLS, AK_IK_SOLVER_TWO_BONE};
    for (int k = 0; k < 4; ++k) {
        ak_transform pose[4];
        rest_pose(sk, pose);
        pose[1].translation = ak_vec3_make(0.65f, 0.0f, 0.0f); /* rest 0.5 */
        pose[2].translation = ak_vec3_make(0.8f, 0.0f, 0.0f);  /* rest 0.6 */
        const size_t n = all[k] == AK_IK_SOLVER_TWO_BONE ? 3 : 4;
        solve_out o = solve(sk, pose, chain, n, ak_vec3_make(0.5f, 0.7f, 0.0f), all[k], NULL);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK_NEAR(pose[1].translation.x, 0.65, 1e-7);
        AK_CHECK_NEAR(pose[2].translation.x, 0.8, 1e-7);
        AK_CHECK(pose_finite(pose, 4));
    }
    ak_skeleton_destroy(sk);
}

/* ---- two-bone ----------------------------------------------------------------------------- */

AK_TEST(two_bone_closed_form_and_pole) {
    /* Hip at the origin, bones a = 1 and b = 0.8 along +x (straight), target at distance
     * d = 1.3 in the xy-plane. Law of cosines: the knee sits at angle
     * alpha = acos((a^2 + d^2 - b^2) / (2 a d)) from the hip->target line, on the pole's side. */
    const double a = 1.0, b = 0.8;
    const ak_vec3 target = ak_vec3_make(0.6f, 1.153256f, 0.0f); /* |target| = 1.3 */
    const double d = sqrt(0.6 * 0.6 + 1.153256 * 1.153256);
    const double alpha = acos((a * a + d * d - b * b) / (2 * a * d));
    const double interior = acos((a * a + b * b - d * d) / (2 * a * b)); /* at the knee */
    for (int side = -1; side <= 1; side += 2) {
        const ak_vec3 pole = ak_vec3_make(0, 0, (float)side); /* bend out of the plane, +z or -z */
        ak_quat qs, qm;
        bool reached = false;
        ak_ik_two_bone_job job = {.start = ak_mat4_identity(),
                                  .mid = ak_mat4_translation(ak_vec3_make(1, 0, 0)),
                                  .end = ak_mat4_translation(ak_vec3_make(1.8f, 0, 0)),
                                  .target = target,
                                  .pole = pole,
                                  .out_start_rot = &qs,
                                  .out_mid_rot = &qm,
                                  .out_reached = &reached};
        AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
        AK_CHECK(reached);
        /* Apply: knee = qs * (1,0,0); ankle = knee + qs * qm * (0.8,0,0). */
        ak_vec3 knee = ak_quat_rotate(qs, ak_vec3_make(1, 0, 0));
        ak_vec3 ankle = ak_vec3_add(knee, ak_quat_rotate(ak_quat_mul(qs, qm), ak_vec3_make(0.8f, 0, 0)));
        AK_CHECK_NEAR(ankle.x, target.x, 1e-5);
        AK_CHECK_NEAR(ankle.y, target.y, 1e-5);
        AK_CHECK_NEAR(ankle.z, target.z, 1e-5);
        /* Closed-form knee: k = a cos(alpha) u + a sin(alpha) w, u along the target, w the pole. */
        double ux = target.x / d, uy = target.y / d;
        AK_CHECK_NEAR(knee.x, a * cos(alpha) * ux, 1e-5);
        AK_CHECK_NEAR(knee.y, a * cos(alpha) * uy, 1e-5);
        AK_CHECK_NEAR(knee.z, side * a * sin(alpha), 1e-5);
        /* Knee interior angle: the mid correction bends by pi - interior. */
        AK_CHECK_NEAR(2 * atan2(sqrt(qm.x * qm.x + qm.y * qm.y + qm.z * qm.z), fabs(qm.w)), PI_D - interior, 1e-5);
        AK_CHECK_NEAR(ak_quat_norm(qs), 1.0, 1e-6);
        AK_CHECK_NEAR(ak_quat_norm(qm), 1.0, 1e-6);
    }
}

/* Bend side with a hinge axis (ak_ik_two_bone_job.mid_axis_signed), against a construction in
 * double: the limb start s0 (turned by some rotation), bones a = 1 and b = 0.8 along each
 * joint's +x, the mid joint turned by beta about its local z (the hinge, mid_axis = +-z), so
 * the input is bent with (mid - start) x (end - mid) along sign(beta) times the hinge. Law of
 * cosines: the knee sits at K = s0 + a cos(alpha) k + a sin(alpha) w (k towards the target, w
 * the pole's part normal to k), the end at the target; the hinge of the solved limb is normal
 * to that triangle, c = (K - s0) x (T - K) normalised, so the joints' frames are fixed up to the
 * hinge's sign: start (x = (K - s0) / a, z = +-c), mid = end (x = (T - K) / b, z = +-c).
 * Unsigned (default): the limb keeps its side, z = sign(beta) c. Signed (ozz's convention, a
 * positive turn about mid_axis opens the joint): (K - s0) x (T - K) along -mid_axis, so
 * z = -sign(mid_axis.z) c whatever the input (straight included). A wrong side leaves the positions right and turns
 * every frame half a turn about its bone (what ozz's harness saw), so the axes are checked. */
AK_TEST(two_bone_bend_side_mid_axis) {
    const double a = 1.0, b = 0.8, d = 1.3;
    const double s0[3] = {0.2, -0.1, 0.3};
    double kd[3] = {0.3, 0.9, -0.4}, pl[3] = {0.2, -0.3, 1.0};
    const double kn = sqrt(kd[0] * kd[0] + kd[1] * kd[1] + kd[2] * kd[2]);
    for (int i = 0; i < 3; ++i) kd[i] /= kn;
    const double pk = pl[0] * kd[0] + pl[1] * kd[1] + pl[2] * kd[2];
    double w[3] = {pl[0] - pk * kd[0], pl[1] - pk * kd[1], pl[2] - pk * kd[2]};
    const double wn = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int i = 0; i < 3; ++i) w[i] /= wn;
    const double alpha = acos((a * a + d * d - b * b) / (2 * a * d));
    double T[3], K[3], u[3], v[3];
    for (int i = 0; i < 3; ++i) {
        T[i] = s0[i] + d * kd[i];
        K[i] = s0[i] + a * cos(alpha) * kd[i] + a * sin(alpha) * w[i];
        u[i] = (K[i] - s0[i]) / a, v[i] = (T[i] - K[i]) / b;
    }
    double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double cn = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    for (int i = 0; i < 3; ++i) c[i] /= cn;

    const ak_quat start_q = ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(0.3f, 0.5f, 0.8f)), 0.7f);
    for (int bent = -1; bent <= 1; ++bent) { /* bent 0: a straight input limb */
        const ak_quat bend_q = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.4f * (float)bent);
        const ak_quat mid_q = ak_quat_mul(start_q, bend_q);
        const ak_vec3 sp = ak_vec3_make((float)s0[0], (float)s0[1], (float)s0[2]);
        const ak_vec3 mp = ak_vec3_add(sp, ak_quat_rotate(start_q, ak_vec3_make((float)a, 0, 0)));
        const ak_vec3 ep = ak_vec3_add(mp, ak_quat_rotate(mid_q, ak_vec3_make((float)b, 0, 0)));
        for (int axis_sign = -1; axis_sign <= 1; axis_sign += 2) {
            for (int sgn = bent == 0; sgn < 2; ++sgn) { /* straight: no input side to keep */
                ak_quat qs, qm;
                bool reached = false;
                ak_ik_two_bone_job job = {
                    .start = ak_transform_to_mat4((ak_transform){sp, start_q, ak_vec3_make(1, 1, 1)}),
                    .mid = ak_transform_to_mat4((ak_transform){mp, mid_q, ak_vec3_make(1, 1, 1)}),
                    .end = ak_transform_to_mat4((ak_transform){ep, mid_q, ak_vec3_make(1, 1, 1)}),
                    .target = ak_vec3_make((float)T[0], (float)T[1], (float)T[2]),
                    .pole = ak_vec3_make((float)pl[0], (float)pl[1], (float)pl[2]),
                    .mid_axis = ak_vec3_make(0, 0, (float)axis_sign),
                    .mid_axis_signed = sgn != 0,
                    .out_start_rot = &qs,
                    .out_mid_rot = &qm,
                    .out_reached = &reached,
                };
                AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
                AK_CHECK(reached);
                /* the batch takes jobs with a mid_axis one by one: the same answer */
                ak_quat bs, bm;
                ak_ik_two_bone_job jb = job;
                jb.out_start_rot = &bs, jb.out_mid_rot = &bm, jb.out_reached = NULL;
                AK_CHECK_EQ(ak_ik_two_bone_run_many(&jb, 1, NULL), AK_OK);
                AK_CHECK(memcmp(&bs, &qs, sizeof qs) == 0 && memcmp(&bm, &qm, sizeof qm) == 0);
                /* the corrected joints' model rotations (local post-multiplied corrections) */
                const ak_quat start_n = ak_quat_mul(start_q, qs);
                const ak_quat mid_n = ak_quat_mul(ak_quat_mul(start_n, bend_q), qm);
                const double zs = sgn ? -axis_sign : bent; /* expected hinge z along zs * c */
                const ak_vec3 sx = ak_quat_rotate(start_n, ak_vec3_make(1, 0, 0)),
                              sz = ak_quat_rotate(start_n, ak_vec3_make(0, 0, 1));
                const ak_vec3 mx = ak_quat_rotate(mid_n, ak_vec3_make(1, 0, 0)),
                              mz = ak_quat_rotate(mid_n, ak_vec3_make(0, 0, 1));
                const double got[4][3] = {{sx.x, sx.y, sx.z}, {sz.x, sz.y, sz.z}, {mx.x, mx.y, mx.z}, {mz.x, mz.y, mz.z}};
                const double want[4][3] = {{u[0], u[1], u[2]},
                                           {zs * c[0], zs * c[1], zs * c[2]},
                                           {v[0], v[1], v[2]},
                                           {zs * c[0], zs * c[1], zs * c[2]}};
                for (int k = 0; k < 4; ++k)
                    for (int i = 0; i < 3; ++i) AK_CHECK_NEAR(got[k][i], want[k][i], 2e-5);
                /* the end joint lands on the target */
                const ak_vec3 kp = ak_vec3_add(sp, ak_vec3_scale(sx, (float)a));
                const ak_vec3 tp = ak_vec3_add(kp, ak_vec3_scale(mx, (float)b));
                AK_CHECK_NEAR(ak_vec3_distance(kp, ak_vec3_make((float)K[0], (float)K[1], (float)K[2])), 0.0, 2e-5);
                AK_CHECK_NEAR(ak_vec3_distance(tp, job.target), 0.0, 2e-5);
            }
        }
    }
}

AK_TEST(two_bone_chain_matches_job_and_limits) {
    /* The chain solver on a leg: hip (ball), knee (hinge about z, bends 0..2.6), ankle. */
    chain_spec s = uniform_chain(3, AK_JOINT_BALL);
    s.lengths[0] = 0.45f, s.lengths[1] = 0.42f;
    s.types[1] = AK_JOINT_HINGE, s.limits[1].axis = ak_vec3_make(0, 0, 1), s.limits[1].min = 0.0f,
    s.limits[1].max = 2.6f;
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[3] = {0, 1, 2};
    ak_rng rng = ak_rng_make(99);
    int ok = 0;
    for (int t = 0; t < 200; ++t) {
        ak_transform goal[3], pose[3];
        random_pose(sk, &rng, goal, false);
        ak_vec3 target = effector_of(goal, 3);
        random_pose(sk, &rng, pose, false);
        ak_ik_chain_job opts = {.pole = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), 1)};
        solve_out o = solve(sk, pose, chain, 3, target, AK_IK_SOLVER_TWO_BONE, &opts);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK_EQ(o.iterations, 0);
        AK_CHECK(lengths_preserved(&s, pose));
        for (int i = 0; i < 3; ++i) AK_CHECK(within_limits(&s, sk, (size_t)i, pose[i], 1e-4));
        ok += o.reached;
        if (!o.reached && getenv("IKDBG")) printf("two-bone miss: err %g tol %g |t| %g\n", o.error, o.tolerance, ak_vec3_length(target));
    }
    /* Knee hinge within 0..2.6 reaches every distance in [|a-b|.., a+b] one way: all reachable. */
    AK_CHECK_MSG(ok == 200, "%d of 200 reached", ok);
    ak_skeleton_destroy(sk);
}

/* A random rigid model matrix (uniform scale 1 or s) placed at pos. */
static ak_mat4 rand_joint_matrix(ak_rng* rng, ak_vec3 pos, float scale) {
    ak_vec3 axis = ak_vec3_make(ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1) + 0.01f);
    ak_mat4 m = ak_mat4_from_quat(ak_quat_from_axis_angle(axis, ak_rng_range(rng, -3.0f, 3.0f)));
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) m.m[4 * c + r] *= scale;
    m.m[12] = pos.x, m.m[13] = pos.y, m.m[14] = pos.z;
    return m;
}

AK_TEST(two_bone_run_many_equals_single_jobs) {
    /* Random limbs (bent, straight, scaled frames), targets near, far and on the start joint,
     * with a mix of the options that leave the SIMD lanes (mid_axis, soft, keep_animation,
     * twist, no pole) and of invalid jobs: every job must get what ak_ik_two_bone_run gives it. */
    enum { N = 2003 };
    ak_rng rng = ak_rng_make(4242);
    ak_ik_two_bone_job* jobs = calloc(N, sizeof *jobs);
    ak_quat* qa = calloc(4 * N, sizeof *qa);
    bool* ra = calloc(2 * N, sizeof *ra);
    if (!jobs || !qa || !ra) {
        AK_CHECK(false);
        free(jobs), free(qa), free(ra);
        return;
    }
    int first_bad = -1;
    for (int i = 0; i < N; ++i) {
        const float scale = (i % 7 == 3) ? 1.7f : 1.0f;
        ak_vec3 s = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1));
        ak_vec3 d1 = ak_vec3_normalize(ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1)));
        ak_vec3 d2 = (i % 11 == 5) ? d1 /* straight limb */
                                   : ak_vec3_normalize(ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                                                                    ak_rng_range(&rng, -1, 1)));
        const float a = ak_rng_range(&rng, 0.3f, 1.2f), b = ak_rng_range(&rng, 0.3f, 1.2f);
        ak_vec3 m = ak_vec3_madd(s, d1, a), e = ak_vec3_madd(m, d2, b);
        const float reach = ak_rng_range(&rng, 0.0f, 1.3f) * (a + b);
        ak_vec3 t = ak_vec3_madd(s, ak_vec3_normalize(ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                                                                    ak_rng_range(&rng, -1, 1))), reach);
        if (i % 97 == 13) t = s; /* target on the start joint */
        ak_ik_two_bone_job j = {
            .start = rand_joint_matrix(&rng, s, scale),
            .mid = rand_joint_matrix(&rng, m, scale),
            .end = rand_joint_matrix(&rng, e, scale),
            .target = t,
            .pole = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1)),
            .out_start_rot = &qa[2 * i],
            .out_mid_rot = &qa[2 * i + 1],
            .out_reached = &ra[i],
        };
        switch (i % 29) {
        case 1: j.mid_axis = ak_vec3_make(0, 0, 1); break;
        case 2: j.soft = 0.2f; break;
        case 3: j.keep_animation = 0.3f; break;
        case 4: j.twist = 0.4f; break;
        case 5: j.pole = ak_vec3_zero(); break;
        case 6: j.end.m[5] = NAN; if (first_bad < 0) first_bad = i; break;  /* invalid: BAD_DATA */
        case 7: j.soft = 1.5f; if (first_bad < 0) first_bad = i; break;     /* invalid: BAD_ARG */
        case 8: j.mid_axis = ak_vec3_make(0.3f, -0.5f, 0.8f), j.mid_axis_signed = true; break;
        default: break;
        }
        jobs[i] = j;
    }
    /* reference: one job at a time, outputs redirected to the second half */
    for (int i = 0; i < N; ++i) qa[2 * N + 2 * i] = qa[2 * N + 2 * i + 1] = ak_quat_make(7, 7, 7, 7);
    for (int i = 0; i < N; ++i) qa[2 * i] = qa[2 * i + 1] = ak_quat_make(7, 7, 7, 7);
    int bad_single = 0;
    for (int i = 0; i < N; ++i) {
        ak_ik_two_bone_job j = jobs[i];
        j.out_start_rot = &qa[2 * N + 2 * i], j.out_mid_rot = &qa[2 * N + 2 * i + 1], j.out_reached = &ra[N + i];
        bad_single += ak_ik_two_bone_run(&j) != AK_OK;
    }
    size_t failed = 0;
    AK_CHECK_EQ(ak_ik_two_bone_run_many(jobs, N, &failed), AK_ERR_BAD_DATA); /* job 6 fails first */
    AK_CHECK_EQ((int)failed, first_bad);
    int exact = 0, worse = 0;
    for (int i = 0; i < N; ++i) {
        const float* x = &qa[2 * i].x;
        const float* y = &qa[2 * N + 2 * i].x;
        bool same = memcmp(x, y, 2 * sizeof(ak_quat)) == 0;
        exact += same;
        if (!same) {
            double dmax = 0;
            for (int k = 0; k < 8; ++k) dmax = fmax(dmax, fabs((double)x[k] - y[k]));
            if (!(dmax < 1e-6)) ++worse;
        }
        AK_CHECK_EQ(ra[i], ra[N + i]);
    }
    /* invalid jobs: nothing written by either (both halves start as 7s) */
    AK_CHECK_EQ(qa[2 * 6].x, 7.0f);
    AK_CHECK_EQ(qa[2 * 7 + 1].w, 7.0f);
    printf("  run_many vs single jobs: %d of %d bit-identical, %d differ by >= 1e-6; %d invalid jobs\n", exact, N, worse,
           bad_single);
    AK_CHECK_EQ(worse, 0);
    AK_CHECK_EQ(exact, N);
    /* empty and NULL */
    AK_CHECK_EQ(ak_ik_two_bone_run_many(NULL, 0, NULL), AK_OK);
    AK_CHECK_EQ(ak_ik_two_bone_run_many(NULL, 3, &failed), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_ik_two_bone_run_many(jobs, 0, &failed), AK_OK);
    AK_CHECK_EQ((int)failed, 0);
    free(jobs), free(qa), free(ra);
}

AK_TEST(two_bone_soft_weight_unreachable) {
    ak_quat qs, qm;
    bool reached = true;
    ak_ik_two_bone_job job = {.start = ak_mat4_identity(),
                              .mid = ak_mat4_translation(ak_vec3_make(0, -1, 0)),
                              .end = ak_mat4_translation(ak_vec3_make(0.3f, -1.9f, 0)),
                              .target = {0, -5, 3},
                              .out_start_rot = &qs,
                              .out_mid_rot = &qm,
                              .out_reached = &reached};
    /* Unreachable: straight towards the target, not reached. */
    AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
    AK_CHECK(!reached);
    const double b = sqrt(0.3 * 0.3 + 0.9 * 0.9), reach = 1.0 + b;
    ak_vec3 knee = ak_quat_rotate(qs, ak_vec3_make(0, -1, 0));
    ak_vec3 ankle = ak_vec3_add(knee, ak_quat_rotate(ak_quat_mul(qs, qm), ak_vec3_make(0.3f, -0.9f, 0)));
    ak_vec3 dir = ak_vec3_normalize(job.target);
    AK_CHECK_NEAR(ankle.x, dir.x * reach, 1e-5);
    AK_CHECK_NEAR(ankle.y, dir.y * reach, 1e-5);
    AK_CHECK_NEAR(ankle.z, dir.z * reach, 1e-5);

    /* Soft: a target exactly at full reach ends short of it, smoothly: with soft = 0.2 the
     * distance is ds + (L - ds)(1 - exp(-(d - ds)/(L - ds))), ds = 0.8 L. */
    job.soft = 0.2f;
    job.target = ak_vec3_scale(dir, (float)reach);
    AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
    AK_CHECK(!reached);
    knee = ak_quat_rotate(qs, ak_vec3_make(0, -1, 0));
    ankle = ak_vec3_add(knee, ak_quat_rotate(ak_quat_mul(qs, qm), ak_vec3_make(0.3f, -0.9f, 0)));
    double ds = 0.8 * reach, want = ds + (reach - ds) * (1 - exp(-(reach - ds) / (reach - ds)));
    AK_CHECK_NEAR(ak_vec3_length(ankle), want, 1e-5);
    AK_CHECK_NEAR(ak_vec3_dot(ak_vec3_normalize(ankle), dir), 1.0, 1e-5);

    /* keep_animation = 1: identity corrections; 0.5: half the angle (nlerp of a small turn). */
    job.soft = 0.0f;
    job.target = ak_vec3_make(0.5f, -1.2f, 0.2f);
    job.keep_animation = 1.0f;
    AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
    AK_CHECK_NEAR(fabs(qs.w), 1.0, 1e-6);
    AK_CHECK_NEAR(fabs(qm.w), 1.0, 1e-6);
    job.keep_animation = 0.0f;
    ak_quat full_s, full_m;
    AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
    full_s = qs, full_m = qm;
    job.keep_animation = 0.5f;
    AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
    ak_quat hs = ak_quat_nlerp(ak_quat_identity(), full_s, 0.5f), hm = ak_quat_nlerp(ak_quat_identity(), full_m, 0.5f);
    AK_CHECK_NEAR(ak_quat_dot(qs, hs), 1.0, 1e-6);
    AK_CHECK_NEAR(ak_quat_dot(qm, hm), 1.0, 1e-6);

    /* Degenerate: target on the start joint, zero-length bones: finite output. */
    job.keep_animation = 0.0f;
    job.target = ak_vec3_zero();
    AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
    AK_CHECK(ak_quat_is_finite(qs) && ak_quat_is_finite(qm));
    job.mid = job.end = ak_mat4_identity();
    job.target = ak_vec3_make(1, 1, 1);
    AK_CHECK_EQ(ak_ik_two_bone_run(&job), AK_OK);
    AK_CHECK(ak_quat_is_finite(qs) && ak_quat_is_finite(qm));
    AK_CHECK(!reached);
}

/* ---- unreachable and degenerate ------------------------------------------------------------ */

AK_TEST(unreachable_straightens) {
    chain_spec s = uniform_chain(5, AK_JOINT_FREE);
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[5] = {0, 1, 2, 3, 4};
    double len = 0;
    for (int i = 0; i < 4; ++i) len += s.lengths[i];
    const ak_vec3 target = ak_vec3_make(1.0f, 3.0f, -2.0f); /* |t| = 3.74 > len = 2.6 */
    const ak_ik_solver all[4] = {AK_IK_SOLVER_CCD, AK_IK_SOLVER_FABRIK, AK_IK_SOLVER_DLS, AK_IK_SOLVER_TWO_BONE};
    for (int k = 0; k < 3; ++k) {
        ak_rng rng = ak_rng_make(5);
        ak_transform pose[5];
        random_pose(sk, &rng, pose, false);
        ak_ik_chain_job opts = {.max_iterations = 500};
        solve_out o = solve(sk, pose, chain, 5, target, all[k], &opts);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(!o.reached);
        AK_CHECK(pose_finite(pose, 5));
        AK_CHECK(lengths_preserved(&s, pose));
        double want = ak_vec3_length(target) - len;
        AK_CHECK_MSG(fabs(o.error - want) < 2e-3 * len, "%s: error %g, remaining distance %g", ak_ik_solver_name(all[k]),
                     o.error, want);
        /* It stops by itself (no oscillation until the budget runs out). */
        AK_CHECK_MSG(o.iterations < 500, "%s used the whole budget", ak_ik_solver_name(all[k]));
        /* Every joint on the root->target line. */
        double p[5][3];
        fk_positions(pose, 5, p);
        ak_vec3 dir = ak_vec3_normalize(target);
        for (int i = 1; i < 5; ++i) {
            double along = p[i][0] * dir.x + p[i][1] * dir.y + p[i][2] * dir.z;
            double off = sqrt(fmax(0, p[i][0] * p[i][0] + p[i][1] * p[i][1] + p[i][2] * p[i][2] - along * along));
            AK_CHECK_MSG(off < 0.03, "%s: joint %d is %g off the line", ak_ik_solver_name(all[k]), i, off);
        }
        /* Solving again from the result changes nothing much (a fixed point). */
        ak_transform again[5];
        memcpy(again, pose, sizeof pose);
        solve_out o2 = solve(sk, again, chain, 5, target, all[k], &opts);
        AK_CHECK(o2.error <= o.error + 1e-4 * len);
    }
    ak_skeleton_destroy(sk);
}

AK_TEST(degenerate_chains) {
    /* One-joint chain: nothing moves, 0 iterations; reached only when already there. */
    chain_spec s = uniform_chain(4, AK_JOINT_FREE);
    s.lengths[1] = 0.0f; /* a zero-length bone in the middle */
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[4] = {0, 1, 2, 3};
    for (int k = 0; k < 4; ++k) {
        ak_ik_solver solver = k < 3 ? iterative[k] : AK_IK_SOLVER_TWO_BONE;
        ak_transform pose[4], before[4];
        rest_pose(sk, pose);
        memcpy(before, pose, sizeof pose);
        if (solver != AK_IK_SOLVER_TWO_BONE) {
            int16_t one[1] = {2};
            solve_out o = solve(sk, pose, one, 1, ak_vec3_make(3, 3, 3), solver, NULL);
            AK_CHECK_EQ(o.r, AK_OK);
            AK_CHECK(!o.reached);
            AK_CHECK_EQ(o.iterations, 0);
            AK_CHECK(memcmp(pose, before, sizeof pose) == 0);
            /* the root's own position (0.5 + 0 along x for joint 2) */
            AK_CHECK_NEAR(o.error, ak_vec3_distance(ak_vec3_make(3, 3, 3), ak_vec3_make(0.5f, 0, 0)), 1e-6);
            o = solve(sk, pose, one, 1, ak_vec3_make(0.5f, 0, 0), solver, NULL);
            AK_CHECK(o.reached);
        }
        /* Zero-length bone inside: reachable target reached, lengths (incl. the zero) kept. */
        const size_t n = solver == AK_IK_SOLVER_TWO_BONE ? 3 : 4;
        rest_pose(sk, pose);
        ak_vec3 target = solver == AK_IK_SOLVER_TWO_BONE ? ak_vec3_make(0.2f, 0.3f, 0.1f) : ak_vec3_make(0.4f, 0.6f, 0.3f);
        ak_ik_chain_job opts = {.max_iterations = 200};
        solve_out o = solve(sk, pose, chain, n, target, solver, &opts);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(pose_finite(pose, 4));
        AK_CHECK(lengths_preserved(&s, pose));
        if (solver != AK_IK_SOLVER_TWO_BONE) AK_CHECK_MSG(o.reached, "%s: error %g", ak_ik_solver_name(solver), o.error);
        /* Target on the root: defined, finite, error never above the start. */
        rest_pose(sk, pose);
        ak_vec3 e0 = effector_of(pose, n);
        o = solve(sk, pose, chain, n, ak_vec3_zero(), solver, &opts);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(pose_finite(pose, 4));
        AK_CHECK(lengths_preserved(&s, pose));
        AK_CHECK(o.error <= ak_vec3_length(e0) + 1e-6);
    }
    ak_skeleton_destroy(sk);

    /* A straight chain and a target on its own line, inside the reach: the Jacobian is
     * singular along the line, CCD's RE is parallel to RD at every joint and FABRIK's passes
     * stay on the line (all three are stuck there as textbook algorithms). The job bends the
     * chain slightly first, so all of them get there. */
    chain_spec line = uniform_chain(4, AK_JOINT_FREE);
    sk = make_chain(&line);
    if (!sk) return;
    for (int k = 0; k < 3; ++k) {
        ak_transform pose[4];
        rest_pose(sk, pose);
        ak_ik_chain_job opts = {.max_iterations = 100};
        solve_out o = solve(sk, pose, chain, 4, ak_vec3_make(1.0f, 0, 0), iterative[k], &opts);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(pose_finite(pose, 4));
        AK_CHECK(lengths_preserved(&line, pose));
        AK_CHECK(o.error <= 0.8f + 1e-5f); /* the straight effector is at 1.8 */
        AK_CHECK_MSG(o.reached, "%s: error %g", ak_ik_solver_name(iterative[k]), o.error);
    }
    ak_skeleton_destroy(sk);

    /* All bones zero-length: everything sits on the root; finite, reached only at the root. */
    chain_spec z = uniform_chain(3, AK_JOINT_FREE);
    z.lengths[0] = z.lengths[1] = 0.0f;
    sk = make_chain(&z);
    if (!sk) return;
    for (int k = 0; k < 4; ++k) {
        ak_ik_solver solver = k < 3 ? iterative[k] : AK_IK_SOLVER_TWO_BONE;
        ak_transform pose[3];
        rest_pose(sk, pose);
        solve_out o = solve(sk, pose, chain, 3, ak_vec3_make(1, 0, 0), solver, NULL);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(pose_finite(pose, 3));
        AK_CHECK(!o.reached);
        AK_CHECK_NEAR(o.error, 1.0, 1e-6);
    }
    ak_skeleton_destroy(sk);
}

AK_TEST(dls_orientation_target) {
    chain_spec s = uniform_chain(6, AK_JOINT_FREE);
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[6] = {0, 1, 2, 3, 4, 5};
    ak_rng rng = ak_rng_make(42);
    int ok = 0;
    for (int t = 0; t < 50; ++t) {
        ak_transform goal[6], pose[6];
        random_pose(sk, &rng, goal, false);
        /* The goal effector's model rotation: product of the local rotations. */
        ak_quat rot = ak_quat_identity();
        for (int i = 0; i < 6; ++i) rot = ak_quat_mul(rot, goal[i].rotation);
        ak_vec3 target = effector_of(goal, 6);
        random_pose(sk, &rng, pose, false);
        ak_ik_chain_job opts = {.target_rotation = &rot, .max_iterations = 100};
        solve_out o = solve(sk, pose, chain, 6, target, AK_IK_SOLVER_DLS, &opts);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(lengths_preserved(&s, pose));
        if (o.reached) {
            ++ok;
            /* independent check of the angle: model rotation from the pose */
            ak_quat got = ak_quat_identity();
            for (int i = 0; i < 6; ++i) got = ak_quat_mul(got, pose[i].rotation);
            AK_CHECK(ak_quat_angle_between(got, rot) <= 1.5e-3f);
            AK_CHECK(o.angle_error <= 1e-3f);
        }
    }
    AK_CHECK_MSG(ok >= 47, "%d of 50 reached with orientation", ok);
    /* Other solvers set the effector's own rotation to the target rotation. */
    ak_transform pose[6];
    rest_pose(sk, pose);
    ak_quat rot = ak_quat_from_axis_angle(ak_vec3_make(1, 2, 3), 0.7f);
    ak_ik_chain_job opts = {.target_rotation = &rot};
    solve_out o = solve(sk, pose, chain, 6, ak_vec3_make(1, 1, 1), AK_IK_SOLVER_FABRIK, &opts);
    AK_CHECK_EQ(o.r, AK_OK);
    AK_CHECK(o.angle_error < 1e-4f);
    ak_skeleton_destroy(sk);
}

/* ---- FABRIK on a tree ---------------------------------------------------------------------- */

/* root -> spine -> {l1 -> l2 -> l3, r1 -> r2 -> r3} */
static ak_skeleton* make_tree(void) {
    ak_joint_desc j[9];
    memset(j, 0, sizeof j);
    const char* names[9] = {"root", "spine", "l1", "l2", "l3", "r1", "r2", "r3", "head"};
    const int parents[9] = {-1, 0, 1, 2, 3, 1, 5, 6, 1};
    const ak_vec3 offs[9] = {{0, 0, 0},  {0, 1, 0},   {0.3f, 0.4f, 0}, {0.5f, 0, 0}, {0.4f, 0, 0},
                             {-0.3f, 0.4f, 0}, {-0.5f, 0, 0}, {-0.4f, 0, 0}, {0, 0.5f, 0}};
    for (int i = 0; i < 9; ++i) {
        j[i].name = names[i];
        j[i].parent = parents[i];
        j[i].rest = ak_transform_identity();
        j[i].rest.translation = offs[i];
    }
    ak_skeleton_desc d = {.joints = j, .joint_count = 9};
    ak_skeleton* sk = NULL;
    ak_skeleton_create(&d, NULL, &sk, NULL);
    return sk;
}

AK_TEST(fabrik_tree) {
    ak_skeleton* sk = make_tree();
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t eff[2] = {4, 7};
    ak_rng rng = ak_rng_make(3);
    int ok = 0;
    for (int t = 0; t < 50; ++t) {
        ak_transform goal[9], pose[9];
        ak_mat4 model[9];
        random_pose(sk, &rng, goal, false);
        ak_skeleton_local_to_model(sk, (ak_transform_cspan)AK_SPAN(goal), (ak_mat4_span)AK_SPAN(model));
        ak_vec3 targets[2] = {ak_mat4_get_translation(model[4]), ak_mat4_get_translation(model[7])};
        random_pose(sk, &rng, pose, false);
        pose[0] = goal[0]; /* above the solved tree: the same in both, so the targets are reachable */
        ak_mat4 before[9];
        ak_skeleton_local_to_model(sk, (ak_transform_cspan)AK_SPAN(pose), (ak_mat4_span)AK_SPAN(before));
        bool reached = false;
        float error = -1;
        size_t iterations = 0;
        ak_ik_fabrik_tree_job job = {.skeleton = sk,
                                     .pose = AK_SPAN(pose),
                                     .root_joint = 1,
                                     .effectors = AK_SPAN(eff),
                                     .targets = AK_SPAN(targets),
                                     .max_iterations = 100,
                                     .scratch = AK_SPAN(scratch),
                                     .out_reached = &reached,
                                     .out_error = &error,
                                     .out_iterations = &iterations};
        AK_CHECK_EQ(ak_ik_fabrik_tree_run(&job), AK_OK);
        AK_CHECK(pose_finite(pose, 9));
        ak_mat4 after[9];
        ak_skeleton_local_to_model(sk, (ak_transform_cspan)AK_SPAN(pose), (ak_mat4_span)AK_SPAN(after));
        /* Root (spine) stays; every bone keeps its length; reported error is the true max. */
        AK_CHECK_NEAR(ak_vec3_distance(ak_mat4_get_translation(after[1]), ak_mat4_get_translation(before[1])), 0, 1e-6);
        const int32_t* par = ak_skeleton_parents(sk).ptr;
        for (int i = 1; i < 9; ++i) {
            float l0 = ak_vec3_distance(ak_mat4_get_translation(before[i]), ak_mat4_get_translation(before[par[i]]));
            float l1 = ak_vec3_distance(ak_mat4_get_translation(after[i]), ak_mat4_get_translation(after[par[i]]));
            AK_CHECK_NEAR(l1, l0, 1e-5 * l0);
        }
        float e0 = ak_vec3_distance(ak_mat4_get_translation(after[4]), targets[0]);
        float e1 = ak_vec3_distance(ak_mat4_get_translation(after[7]), targets[1]);
        AK_CHECK_NEAR(error, fmaxf(e0, e1), 1e-5);
        ok += reached;
    }
    AK_CHECK_MSG(ok >= 45, "%d of 50 trees reached", ok);

    /* Validity, one case per rule. */
    ak_transform pose[9];
    rest_pose(sk, pose);
    ak_vec3 targets[2] = {{1, 1, 0}, {-1, 1, 0}};
    const ak_ik_fabrik_tree_job good = {.skeleton = sk,
                                        .pose = AK_SPAN(pose),
                                        .root_joint = 1,
                                        .effectors = AK_SPAN(eff),
                                        .targets = AK_SPAN(targets),
                                        .scratch = AK_SPAN(scratch)};
    ak_ik_fabrik_tree_job j, zero;
    memset(&zero, 0, sizeof zero);
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&good), AK_OK);
    j = good, j.effectors.count = 0;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_NULL_ARG);
    j = good, j.targets.count = 1;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_SPAN_SMALL);
    j = good, j.pose.count = 8;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_SPAN_SMALL);
    j = good, j.root_joint = 9;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_BAD_INDEX);
    int16_t bad_eff[2] = {4, 12}, dup[2] = {4, 4}, off_tree[2] = {4, 8};
    j = good, j.effectors = (ak_i16_cspan)AK_SPAN(bad_eff);
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_BAD_INDEX);
    j = good, j.effectors = (ak_i16_cspan)AK_SPAN(dup);
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_DUPLICATE);
    j = good, j.effectors = (ak_i16_cspan)AK_SPAN(off_tree), j.root_joint = 2;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_NOT_FOUND);
    targets[1].x = NAN;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&good), AK_ERR_BAD_DATA);
    targets[1].x = -1;
    pose[0].translation.y = INFINITY; /* an ancestor of the root joint */
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&good), AK_ERR_BAD_DATA);
    rest_pose(sk, pose);
    j = good, j.tolerance = -1;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_BAD_ARG);
    j = good, j.scratch.ptr = NULL;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_NULL_ARG);
    j = good, j.scratch.count = ak_ik_fabrik_tree_scratch_size(9) - 1;
    AK_CHECK_EQ(ak_ik_fabrik_tree_validate(&j), AK_ERR_SPAN_SMALL);
    ak_skeleton_destroy(sk);
}

/* ---- straight chains, targets on their own line ------------------------------------------ */

/* Distance from the root of the end of nb equal bones of length a, each bent by beta from its
 * parent in one plane (a regular polygon's chord): a |sin(nb beta / 2) / sin(beta / 2)|. */
static double curl_reach(int nb, double a, double beta) {
    if (beta < 1e-12) return nb * a;
    return a * fabs(sin(nb * beta / 2) / sin(beta / 2));
}

/* A straight chain pointing through its target is the singular configuration of CCD (RE is
 * parallel to RD at every joint), FABRIK (the passes keep the chain on its line) and DLS (no
 * Jacobian column along the line). Chains of nb = 2..10 equal bones lie straight along their
 * parent's +x (the base joint, not in the chain, either at rest or turned to an oblique
 * direction); the target lies on the chain's line at 5%, 10%, ..., 95% of its length. Joint
 * variants: all free; all unlimited hinges; a free or unlimited-hinge root with hinges limited
 * to one side ([0, 3.1] or [-3.1, 0]); a ball root (cone 2 rad) over limited hinges whose axis
 * is oblique to the chain. Every target is reachable: the test finds, in double precision, a
 * uniform bend beta in [0, 3.1] of the non-root joints whose chord equals the target
 * distance (bent within the hinges' allowed side; the root then turns the chord onto the
 * line). Every solver must reach every target with the default budget and tolerance, and
 * keep bone lengths and limits. */
AK_TEST(straight_chain_targets_on_its_line) {
    enum { VARIANTS = 6 };
    const float side_limit = 3.1f;
    int misses[3] = {0, 0, 0}, total = 0;
    size_t most[3] = {0, 0, 0};
    for (int nb = 2; nb <= 10; ++nb) {
        const size_t count = (size_t)nb + 2; /* base + nb + 1 chain joints */
        const double a = 0.2 + 0.05 * nb;
        for (int variant = 0; variant < VARIANTS; ++variant) {
            chain_spec s;
            memset(&s, 0, sizeof s);
            s.count = count;
            s.lengths[0] = 0.3f;
            for (int i = 1; i <= nb; ++i) s.lengths[i] = (float)a;
            const ak_vec3 hinge_axis = variant >= 4 ? ak_vec3_normalize(ak_vec3_make(0, 0.6f, 0.8f)) : ak_vec3_make(0, 0, 1);
            for (size_t i = 1; i < count; ++i) {
                const bool root = i == 1, effector = i + 1 == count;
                ak_joint_type t = AK_JOINT_FREE;
                ak_joint_limits l;
                memset(&l, 0, sizeof l);
                if (effector) {
                    t = AK_JOINT_FREE;
                } else if (variant == 1 || (root && (variant == 2 || variant == 3))) {
                    t = AK_JOINT_HINGE, l.axis = hinge_axis; /* unlimited */
                } else if (root && variant == 4) {
                    t = AK_JOINT_FREE;
                } else if (root && variant == 5) {
                    t = AK_JOINT_BALL, l.axis = ak_vec3_make(1, 0, 0), l.cone_angle = 2.0f;
                } else if (variant >= 2) {
                    t = AK_JOINT_HINGE, l.axis = hinge_axis;
                    l.min = variant == 3 ? -side_limit : 0.0f;
                    l.max = variant == 3 ? 0.0f : side_limit;
                }
                s.types[i] = t;
                s.limits[i] = l;
            }
            ak_skeleton* sk = make_chain(&s);
            if (!sk) {
                AK_CHECK(sk != NULL);
                return;
            }
            int16_t chain[MAXJ];
            for (size_t i = 1; i < count; ++i) chain[i - 1] = (int16_t)i;
            const size_t chain_count = count - 1;
            for (int oblique = 0; oblique < 2; ++oblique) {
                const ak_quat base_rot = oblique ? ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(0.3f, 0.5f, 0.8f)), 1.0f)
                                                 : ak_quat_identity();
                for (int pct = 5; pct <= 95; pct += 5) {
                    const double d = nb * a * pct / 100.0;
                    /* the witness: curl_reach decreases from nb a (beta = 0) to its first zero
                     * at 2 pi / nb, or to beta = 3.1 for two bones */
                    double lo = 0.0, hi = fmin(2 * PI_D / nb, side_limit);
                    AK_CHECK_MSG(curl_reach(nb, a, hi) <= d, "%d bones, %d%%: no witness", nb, pct);
                    for (int it = 0; it < 60; ++it) {
                        double mid = 0.5 * (lo + hi);
                        if (curl_reach(nb, a, mid) > d) lo = mid;
                        else hi = mid;
                    }
                    AK_CHECK_NEAR(curl_reach(nb, a, hi), d, 1e-9);
                    for (int k = 0; k < 3; ++k) {
                        ak_transform pose[MAXJ];
                        rest_pose(sk, pose);
                        pose[0].rotation = base_rot;
                        double p[MAXJ][3];
                        fk_positions(pose, count, p);
                        const double* r = p[1];
                        const double* e = p[count - 1];
                        ak_vec3 target = ak_vec3_make((float)(r[0] + (e[0] - r[0]) * pct / 100.0),
                                                      (float)(r[1] + (e[1] - r[1]) * pct / 100.0),
                                                      (float)(r[2] + (e[2] - r[2]) * pct / 100.0));
                        solve_out o = solve(sk, pose, chain, chain_count, target, iterative[k], NULL); /* defaults */
                        AK_CHECK_EQ(o.r, AK_OK);
                        ++total;
                        if (o.iterations > most[k]) most[k] = o.iterations;
                        bool ok = pose_finite(pose, count) && lengths_preserved(&s, pose);
                        for (size_t i = 1; i < count; ++i) ok = ok && within_limits(&s, sk, i, pose[i], 1e-4);
                        AK_CHECK_MSG(ok, "%s, %d bones, variant %d: lengths or limits broken",
                                     ak_ik_solver_name(iterative[k]), nb, variant);
                        if (!o.reached) {
                            ++misses[k];
                            if (misses[k] <= 4 || getenv("IKDBG"))
                                printf("  %s missed: %d bones, variant %d, oblique %d, %d%%: error %g (tolerance %g), "
                                       "%zu iterations\n",
                                       ak_ik_solver_name(iterative[k]), nb, variant, oblique, pct, o.error,
                                       o.tolerance, o.iterations);
                        }
                    }
                }
            }
            ak_skeleton_destroy(sk);
        }
    }
    printf("  targets on the line: %d per solver; most iterations used: ccd %zu, fabrik %zu, dls %zu\n", total / 3,
           most[0], most[1], most[2]);
    for (int k = 0; k < 3; ++k)
        AK_CHECK_MSG(misses[k] == 0, "%s: %d of %d targets on the chain's line missed", ak_ik_solver_name(iterative[k]),
                     misses[k], total / 3);
}


/* Bones of 1e30 (squared distances overflow float) and of 1e-30 (squared distances vanish
 * under any fixed threshold): the job solves in a scaled frame, so reachable targets are
 * reached, unreachable ones are not, and every reported number is finite. The oracles are
 * the scale-free answers: the same chain with unit bones, scaled. */
AK_TEST(extreme_scales) {
    const float scales[] = {1e30f, 3e35f, 1e-30f, 1.0f};
    for (size_t si = 0; si < sizeof scales / sizeof scales[0]; ++si) {
        const float k = scales[si];
        chain_spec s = uniform_chain(4, AK_JOINT_FREE);
        for (int i = 0; i < 3; ++i) s.lengths[i] = k; /* reach 3k */
        ak_skeleton* sk = make_chain(&s);
        if (!sk) {
            AK_CHECK(sk != NULL);
            return;
        }
        int16_t chain[4] = {0, 1, 2, 3};
        const float len = ak_ik_chain_length(sk, (ak_transform_cspan){ak_skeleton_rest_pose(sk).ptr, 4},
                                             (ak_i16_cspan){chain, 4});
        AK_CHECK_MSG(isfinite(len) && fabs(len - 3.0 * k) <= 1e-6 * 3.0 * k, "scale %g: chain length %g", k, len);
        for (int k2 = 0; k2 < 4; ++k2) {
            const ak_ik_solver solver = k2 < 3 ? iterative[k2] : AK_IK_SOLVER_FABRIK;
            /* reachable (1.2, 1.5, 0.4) k; unreachable (5, 0, 0) k: error 2k */
            const ak_vec3 near = ak_vec3_make(1.2f * k, 1.5f * k, 0.4f * k), far = ak_vec3_make(5.0f * k, 0, 0);
            ak_transform pose[4];
            rest_pose(sk, pose);
            pose[1].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.4f);
            solve_out o = solve(sk, pose, chain, 4, k2 == 3 ? far : near, solver, NULL);
            AK_CHECK_EQ(o.r, AK_OK);
            AK_CHECK_MSG(isfinite(o.error) && isfinite(o.tolerance) && o.tolerance < 1e-3 * k,
                         "scale %g %s: error %g tolerance %g", k, ak_ik_solver_name(solver), o.error, o.tolerance);
            AK_CHECK(pose_finite(pose, 4));
            if (k2 < 3) {
                AK_CHECK_MSG(o.reached && o.error <= o.tolerance, "scale %g %s: not reached, error %g (tolerance %g)",
                             k, ak_ik_solver_name(solver), o.error, o.tolerance);
            } else {
                AK_CHECK_MSG(!o.reached, "scale %g: an unreachable target reported reached", k);
                AK_CHECK_MSG(fabs(o.error - 2.0 * k) <= 1e-4 * k, "scale %g: error %g, want %g", k, o.error, 2.0 * k);
            }
            /* the reported error is the true distance (computed here in double) */
            double p[MAXJ][3];
            fk_positions(pose, 4, p);
            const ak_vec3 t = k2 == 3 ? far : near;
            double tt[3] = {t.x, t.y, t.z};
            AK_CHECK_MSG(fabs(dist3(p[3], tt) - o.error) <= 1e-5 * k, "scale %g: error %g vs %g", k, o.error, dist3(p[3], tt));
        }
        /* the FABRIK tree job, one effector: same answers */
        for (int far_case = 0; far_case < 2; ++far_case) {
            ak_transform pose[4];
            rest_pose(sk, pose);
            pose[1].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.4f);
            int16_t eff[1] = {3};
            ak_vec3 tg[1] = {far_case ? ak_vec3_make(5.0f * k, 0, 0) : ak_vec3_make(1.2f * k, 1.5f * k, 0.4f * k)};
            bool reached = !far_case;
            float error = -1.0f;
            ak_ik_fabrik_tree_job tj = {.skeleton = sk, .pose = AK_SPAN(pose), .root_joint = 0,
                                        .effectors = AK_SPAN(eff), .targets = AK_SPAN(tg),
                                        .scratch = AK_SPAN(scratch), .out_reached = &reached, .out_error = &error};
            AK_CHECK_EQ(ak_ik_fabrik_tree_run(&tj), AK_OK);
            AK_CHECK_MSG(isfinite(error) && reached == !far_case, "tree, scale %g, far %d: reached %d error %g", k,
                         far_case, reached, error);
            if (far_case) AK_CHECK_MSG(fabs(error - 2.0 * k) <= 1e-4 * k, "tree, scale %g: error %g", k, error);
            else AK_CHECK(error <= 1e-4 * 3.0 * k);
        }
        ak_skeleton_destroy(sk);
    }
    /* Chain positions beyond float range (two bones of 3e38 along x): rejected, not inf. */
    chain_spec big = uniform_chain(3, AK_JOINT_FREE);
    big.lengths[0] = big.lengths[1] = 3e38f;
    ak_skeleton* sk = make_chain(&big);
    if (sk) {
        int16_t chain[3] = {0, 1, 2};
        ak_transform pose[3];
        rest_pose(sk, pose);
        solve_out o = solve(sk, pose, chain, 3, ak_vec3_make(1, 0, 0), AK_IK_SOLVER_CCD, NULL);
        AK_CHECK_EQ(o.r, AK_ERR_BAD_DATA);
        ak_skeleton_destroy(sk);
    }
}

/* ---- DLS on a straight limb, targets on and near its line (issue 27) ----------------------- */

/* builtin:humanoid's left arm at rest, rebuilt here as the builtin defines it (test_ik links
 * only the ik module; test_cli_ik runs the builtin itself): shoulder (0.19, 1.42, 0) under a
 * chest joint, bones 0.28 and 0.26 along d = (1, -1, 0) / sqrt 2, identity rest rotations; a
 * ball shoulder (cone 2.4 about d, twist +-2), the elbow a hinge about d x Z limited to
 * [0, 145] degrees (so targets on the line are reachable from 30.3% of the reach, the law
 * of cosines), a ball wrist (cone 1.2, twist +-0.8). */
typedef struct straight_arm {
    ak_skeleton* skeleton;
    int16_t chain[3];
    size_t joint_count;
    ak_transform rest[4];
    double shoulder[3], dir[3], reach;
} straight_arm;

static bool straight_arm_make(straight_arm* a) {
    memset(a, 0, sizeof *a);
    const float c45 = 0.70710678f;
    const ak_vec3 d = ak_vec3_make(c45, -c45, 0.0f), elbow_axis = ak_vec3_cross(d, ak_vec3_make(0, 0, 1));
    ak_joint_desc j[4];
    memset(j, 0, sizeof j);
    const char* names[4] = {"chest", "left_shoulder", "left_elbow", "left_wrist"};
    const ak_vec3 offsets[4] = {ak_vec3_make(0, 1.3f, 0), ak_vec3_make(0.19f, 0.12f, 0), ak_vec3_scale(d, 0.28f),
                                ak_vec3_scale(d, 0.26f)};
    for (int i = 0; i < 4; ++i) {
        j[i].name = names[i];
        j[i].parent = i - 1;
        j[i].rest = ak_transform_identity();
        j[i].rest.translation = offsets[i];
    }
    j[1].type = AK_JOINT_BALL, j[1].limits = (ak_joint_limits){.axis = d, .cone_angle = 2.4f, .twist_min = -2.0f, .twist_max = 2.0f};
    j[2].type = AK_JOINT_HINGE, j[2].limits = (ak_joint_limits){.axis = elbow_axis, .min = 0.0f, .max = 145.0f * (float)PI_D / 180.0f};
    j[3].type = AK_JOINT_BALL, j[3].limits = (ak_joint_limits){.axis = d, .cone_angle = 1.2f, .twist_min = -0.8f, .twist_max = 0.8f};
    ak_skeleton_desc desc = {.joints = j, .joint_count = 4};
    if (ak_skeleton_create(&desc, NULL, &a->skeleton, NULL) != AK_OK) return false;
    a->joint_count = 4;
    a->chain[0] = 1, a->chain[1] = 2, a->chain[2] = 3;
    rest_pose(a->skeleton, a->rest);
    const double h = sqrt(0.5);
    a->shoulder[0] = 0.19, a->shoulder[1] = 1.42, a->shoulder[2] = 0.0;
    a->dir[0] = h, a->dir[1] = -h, a->dir[2] = 0.0;
    a->reach = 0.28 + 0.26;
    return true;
}

/* The point at fraction f of the reach along the straight arm, rounded to float. */
static ak_vec3 straight_arm_point(const straight_arm* a, double f) {
    return ak_vec3_make((float)(a->shoulder[0] + a->dir[0] * f * a->reach),
                        (float)(a->shoulder[1] + a->dir[1] * f * a->reach),
                        (float)(a->shoulder[2] + a->dir[2] * f * a->reach));
}

/* Chain positions of a pose; bone lengths kept (1e-5), elbow flexion within [0, 145] degrees
 * (the angle between the bones, by the test's own arithmetic in double). */
static bool straight_arm_pose_ok(const straight_arm* a, const ak_transform* pose, double out[3][3]) {
    ak_vec3 p[3];
    if (!pose_finite(pose, a->joint_count) ||
        ak_ik_chain_positions(a->skeleton, (ak_transform_cspan){pose, a->joint_count},
                              (ak_i16_cspan){a->chain, 3}, (ak_vec3_span)AK_SPAN(p)) != AK_OK)
        return false;
    for (int k = 0; k < 3; ++k) out[k][0] = p[k].x, out[k][1] = p[k].y, out[k][2] = p[k].z;
    const double u[3] = {out[1][0] - out[0][0], out[1][1] - out[0][1], out[1][2] - out[0][2]};
    const double v[3] = {out[2][0] - out[1][0], out[2][1] - out[1][1], out[2][2] - out[1][2]};
    const double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]), lv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const double cosb = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (lu * lv);
    return fabs(lu - 0.28) < 1e-5 && fabs(lv - 0.26) < 1e-5 && acos(fmax(-1.0, fmin(1.0, cosb))) <= 145.0 * PI_D / 180.0 + 1e-4;
}

/* Target k of the near-line series: at a random 35..97% of the reach on the straight arm's
 * line, then (k % 4) exactly as float rounds the line, a few float steps (nextafterf) off
 * in each coordinate, or 1e-7..1e-5 or 1e-5..1e-3 of the reach off in a random direction. */
static ak_vec3 near_line_target(const straight_arm* a, ak_rng* rng, int k, double* out_f) {
    const double f = 0.35 + 0.62 * ak_rng_double(rng);
    ak_vec3 t = straight_arm_point(a, f);
    if (k % 4 == 1) {
        float* c = &t.x;
        for (int i = 0; i < 3; ++i) {
            const int steps = (int)(ak_rng_u32(rng) % 17) - 8;
            for (int s = 0; s < abs(steps); ++s) c[i] = nextafterf(c[i], steps > 0 ? INFINITY : -INFINITY);
        }
    } else if (k % 4 >= 2) {
        const double lo = k % 4 == 2 ? -7.0 : -5.0;
        const double size = a->reach * pow(10.0, lo + 2.0 * ak_rng_double(rng));
        const ak_vec3 d =
            ak_vec3_normalize(ak_vec3_make(ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1)));
        t = ak_vec3_make((float)(t.x + d.x * size), (float)(t.y + d.y * size), (float)(t.z + d.z * size));
    }
    *out_f = f;
    return t;
}

/* The issue's case: the arm straight (A-pose rest), the target 5% of the reach in from the
 * wrist, on the arm's line and 1e-5 off it (0.552754, 1.057246, 1e-5 is what the CLI got: error
 * 2.7e-2, the arm straight and pointing at the target, stuck on the saddle). */
AK_TEST(dls_straight_arm_issue_case) {
    straight_arm a;
    if (!straight_arm_make(&a)) {
        AK_CHECK_MSG(false, "the straight arm could not be built");
        ak_skeleton_destroy(a.skeleton);
        return;
    }
    const ak_vec3 on = straight_arm_point(&a, 0.95);
    const ak_vec3 targets[3] = {on, ak_vec3_make(0.552754f, 1.057246f, 1e-5f), ak_vec3_make(on.x, on.y, 1e-4f)};
    for (int k = 0; k < 3; ++k) {
        ak_transform pose[4];
        memcpy(pose, a.rest, sizeof pose);
        solve_out o = solve(a.skeleton, pose, a.chain, 3, targets[k], AK_IK_SOLVER_DLS, NULL);
        double p[3][3];
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(straight_arm_pose_ok(&a, pose, p));
        const double want[3] = {targets[k].x, targets[k].y, targets[k].z};
        AK_CHECK_MSG(o.reached && dist3(p[2], want) <= o.tolerance, "target %d: error %g (tolerance %g), %zu iterations", k,
                     o.error, o.tolerance, o.iterations);
        printf("  5%% in from the straight wrist, target %d: error %.3g, %zu iterations\n", k, o.error, o.iterations);
    }
    ak_skeleton_destroy(a.skeleton);
}

/* 100 targets on and near the straight arm's line, 35..97% of the reach: exactly as float
 * rounds the line, a few float steps (nextafterf) off in each coordinate, and offsets of
 * 1e-7..1e-5 and 1e-5..1e-3 of the reach in random directions (fixed seed); every fifth starts
 * from an elbow bent by 1e-6..1e-2 rad instead of straight (nearly singular Jacobian). DLS must
 * reach every one with the default budget and tolerance, within the joints' limits. Then
 * nearby targets give nearby poses: the target on the line and 1e-5 of the reach off it put
 * the elbow within 1e-3 of the reach of each other. */
AK_TEST(dls_straight_arm_near_its_line) {
    straight_arm a;
    if (!straight_arm_make(&a)) {
        AK_CHECK_MSG(false, "the straight arm could not be built");
        ak_skeleton_destroy(a.skeleton);
        return;
    }
    const ak_skeleton* sk = a.skeleton;
    const int elbow = a.chain[1];
    const ak_vec3 elbow_axis = ak_skeleton_joint_limits(sk, (size_t)elbow).axis;
    ak_rng rng = ak_rng_make(27);
    int misses = 0;
    size_t most = 0, total_iterations = 0;
    for (int k = 0; k < 100; ++k) {
        double f;
        const ak_vec3 t = near_line_target(&a, &rng, k, &f);
        ak_transform pose[4];
        memcpy(pose, a.rest, sizeof pose);
        if (k % 5 == 4) {
            const float bend = (float)pow(10.0, -6.0 + 4.0 * ak_rng_double(&rng));
            pose[elbow].rotation = ak_quat_mul(a.rest[elbow].rotation, ak_quat_from_axis_angle(elbow_axis, bend));
        }
        solve_out o = solve(sk, pose, a.chain, 3, t, AK_IK_SOLVER_DLS, NULL);
        AK_CHECK_EQ(o.r, AK_OK);
        double p[3][3];
        AK_CHECK_MSG(straight_arm_pose_ok(&a, pose, p), "target %d: lengths or elbow limit broken", k);
        most = o.iterations > most ? o.iterations : most;
        total_iterations += o.iterations;
        if (!o.reached) {
            ++misses;
            if (misses <= 5)
                printf("  missed target %d (%.9g, %.9g, %.9g), %.3f of the reach: error %g, %zu iterations\n", k, t.x, t.y,
                       t.z, f, o.error, o.iterations);
        }
    }
    printf("  100 targets on and near the straight arm's line: %d missed, iterations mean %.1f, most %zu\n", misses,
           (double)total_iterations / 100.0, most);
    AK_CHECK_EQ(misses, 0);

    for (int k = 0; k < 3; ++k) {
        const double f = 0.5 + 0.2 * k;
        const ak_vec3 t0 = straight_arm_point(&a, f);
        const float off = (float)(1e-5 * a.reach);
        const ak_vec3 t1 = k == 1 ? ak_vec3_make(t0.x + off * 0.70710678f, t0.y + off * 0.70710678f, t0.z)
                                  : ak_vec3_make(t0.x, t0.y, t0.z + off);
        ak_transform p0[4], p1[4];
        memcpy(p0, a.rest, sizeof p0);
        memcpy(p1, a.rest, sizeof p1);
        solve_out o0 = solve(sk, p0, a.chain, 3, t0, AK_IK_SOLVER_DLS, NULL);
        solve_out o1 = solve(sk, p1, a.chain, 3, t1, AK_IK_SOLVER_DLS, NULL);
        double q0[3][3], q1[3][3];
        AK_CHECK(straight_arm_pose_ok(&a, p0, q0) && straight_arm_pose_ok(&a, p1, q1));
        AK_CHECK(o0.reached && o1.reached);
        AK_CHECK_MSG(dist3(q0[1], q1[1]) <= 1e-3 * a.reach, "%.2f of the reach: the elbows are %g apart", f,
                     dist3(q0[1], q1[1]));
    }
    ak_skeleton_destroy(a.skeleton);
}

/* The same 100 near-line targets (straight starts) for CCD and FABRIK: they curl the chain
 * for a target on its line before iterating, and for one near it once they stall on the
 * line, pointing at the target. */
AK_TEST(ccd_fabrik_straight_arm_near_its_line) {
    straight_arm a;
    if (!straight_arm_make(&a)) {
        AK_CHECK_MSG(false, "the straight arm could not be built");
        ak_skeleton_destroy(a.skeleton);
        return;
    }
    for (int s = 0; s < 2; ++s) {
        const ak_ik_solver solver = s == 0 ? AK_IK_SOLVER_CCD : AK_IK_SOLVER_FABRIK;
        ak_rng rng = ak_rng_make(27);
        int misses = 0;
        size_t most = 0;
        for (int k = 0; k < 100; ++k) {
            double f;
            const ak_vec3 t = near_line_target(&a, &rng, k, &f);
            ak_transform pose[4];
            memcpy(pose, a.rest, sizeof pose);
            solve_out o = solve(a.skeleton, pose, a.chain, 3, t, solver, NULL);
            AK_CHECK_EQ(o.r, AK_OK);
            double p[3][3];
            AK_CHECK_MSG(straight_arm_pose_ok(&a, pose, p), "%s, target %d: lengths or elbow limit broken",
                         ak_ik_solver_name(solver), k);
            most = o.iterations > most ? o.iterations : most;
            if (!o.reached && ++misses <= 3)
                printf("  %s missed target %d (%.9g, %.9g, %.9g): error %g, %zu iterations\n", ak_ik_solver_name(solver), k,
                       t.x, t.y, t.z, o.error, o.iterations);
        }
        printf("  %s: %d of 100 near-line targets missed, most iterations %zu\n", ak_ik_solver_name(solver), misses, most);
        AK_CHECK_EQ(misses, 0);
    }
    ak_skeleton_destroy(a.skeleton);
}

/* Nearly straight starts that the saddle escape leaves alone (the elbow bent 5e-3..0.2 rad,
 * beyond its 1e-3-of-the-length test), targets on the line at 35..97% of the reach: the
 * Jacobian is nearly singular along the line, and the damping must still get there within
 * the default budget. */
AK_TEST(dls_nearly_straight_arm) {
    straight_arm a;
    if (!straight_arm_make(&a)) {
        AK_CHECK_MSG(false, "the straight arm could not be built");
        ak_skeleton_destroy(a.skeleton);
        return;
    }
    const int elbow = a.chain[1];
    const ak_vec3 elbow_axis = ak_skeleton_joint_limits(a.skeleton, (size_t)elbow).axis;
    ak_rng rng = ak_rng_make(2727);
    int misses = 0;
    size_t most = 0, total = 0;
    for (int k = 0; k < 60; ++k) {
        const double f = 0.35 + 0.62 * ak_rng_double(&rng);
        const float bend = (float)(5e-3 * pow(40.0, ak_rng_double(&rng)));
        ak_transform pose[4];
        memcpy(pose, a.rest, sizeof pose);
        pose[elbow].rotation = ak_quat_mul(a.rest[elbow].rotation, ak_quat_from_axis_angle(elbow_axis, bend));
        const ak_vec3 t = straight_arm_point(&a, f);
        solve_out o = solve(a.skeleton, pose, a.chain, 3, t, AK_IK_SOLVER_DLS, NULL);
        AK_CHECK_EQ(o.r, AK_OK);
        double p[3][3];
        AK_CHECK(straight_arm_pose_ok(&a, pose, p));
        most = o.iterations > most ? o.iterations : most;
        total += o.iterations;
        if (!o.reached && ++misses <= 3)
            printf("  missed: bend %g, %.3f of the reach: error %g, %zu iterations\n", bend, f, o.error, o.iterations);
    }
    printf("  60 nearly straight starts: %d missed, iterations mean %.1f, most %zu\n", misses, (double)total / 60.0, most);
    AK_CHECK_EQ(misses, 0);
    ak_skeleton_destroy(a.skeleton);
}

/* A plain straight chain of three free joints (bones 0.5, 0.6 along +x, no limits): targets
 * on and near its line reach the same way (the saddle is not a matter of the arm's limits). */
AK_TEST(dls_straight_free_chain_near_its_line) {
    chain_spec s = uniform_chain(3, AK_JOINT_FREE);
    ak_skeleton* sk = make_chain(&s);
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    int16_t chain[3] = {0, 1, 2};
    const double reach = (double)s.lengths[0] + s.lengths[1];
    ak_rng rng = ak_rng_make(2705);
    int misses = 0;
    for (int k = 0; k < 40; ++k) {
        const double f = 0.15 + 0.83 * ak_rng_double(&rng); /* the reach is 0.1 .. 1.1 */
        const double size = k % 2 ? reach * pow(10.0, -7.0 + 4.0 * ak_rng_double(&rng)) : 0.0;
        const ak_vec3 d = ak_vec3_normalize(ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1)));
        const ak_vec3 t = ak_vec3_make((float)(f * reach + d.x * size), (float)(d.y * size), (float)(d.z * size));
        ak_transform pose[3];
        rest_pose(sk, pose);
        solve_out o = solve(sk, pose, chain, 3, t, AK_IK_SOLVER_DLS, NULL);
        AK_CHECK_EQ(o.r, AK_OK);
        AK_CHECK(pose_finite(pose, 3) && lengths_preserved(&s, pose));
        if (!o.reached && ++misses <= 3)
            printf("  missed (%.9g, %.9g, %.9g): error %g, %zu iterations\n", t.x, t.y, t.z, o.error, o.iterations);
    }
    AK_CHECK_EQ(misses, 0);
    ak_skeleton_destroy(sk);
}

/* Beyond the reach, on, near and off the straight arm's line (1.001 to 1000 reaches): not
 * reached, no NaN, the arm points at the target (wrist on the shoulder->target ray within
 * 1e-3 rad) and the error is the distance minus the reach. Off the line, the target stands
 * 135 degrees from the arm (near the shoulder's 2.4 rad cone): DLS turns the arm there in
 * 30-50 steps, bending the elbow on the way and straightening it at Gauss-Newton's linear
 * rate, so it gets 1e-2 rad (5e-3 at 1000 reaches; the error still within tolerance). */
AK_TEST(dls_straight_arm_unreachable) {
    straight_arm a;
    if (!straight_arm_make(&a)) {
        AK_CHECK_MSG(false, "the straight arm could not be built");
        ak_skeleton_destroy(a.skeleton);
        return;
    }
    const double fs[4] = {1.001, 1.05, 2.0, 1000.0};
    for (int i = 0; i < 4; ++i) {
        for (int v = 0; v < 3; ++v) {
            ak_vec3 t = straight_arm_point(&a, fs[i]);
            if (v == 1) t.z += (float)(1e-5 * a.reach);
            if (v == 2) t = ak_vec3_make((float)a.shoulder[0], (float)(a.shoulder[1] + fs[i] * a.reach), 0.3f * (float)a.reach);
            ak_transform pose[4];
            memcpy(pose, a.rest, sizeof pose);
            solve_out o = solve(a.skeleton, pose, a.chain, 3, t, AK_IK_SOLVER_DLS, NULL);
            AK_CHECK_EQ(o.r, AK_OK);
            double p[3][3];
            AK_CHECK(straight_arm_pose_ok(&a, pose, p));
            AK_CHECK(!o.reached && ak_finitef(o.error));
            const double td[3] = {t.x - p[0][0], t.y - p[0][1], t.z - p[0][2]};
            const double wd[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
            const double lt = sqrt(td[0] * td[0] + td[1] * td[1] + td[2] * td[2]);
            const double cx = td[1] * wd[2] - td[2] * wd[1], cy = td[2] * wd[0] - td[0] * wd[2], cz = td[0] * wd[1] - td[1] * wd[0];
            const double angle = atan2(sqrt(cx * cx + cy * cy + cz * cz), td[0] * wd[0] + td[1] * wd[1] + td[2] * wd[2]);
            AK_CHECK_MSG(angle < (v == 2 ? 1e-2 : 1e-3), "%g reaches, variant %d: the arm is %g rad off the target", fs[i],
                         v, angle);
            if (getenv("IKDBG")) printf("   %g reaches, variant %d: %g rad off, %zu iterations\n", fs[i], v, angle, o.iterations);
            AK_CHECK_MSG(fabs(o.error - (lt - a.reach)) <= o.tolerance + 1e-6 * lt,
                         "%g reaches, variant %d: error %g, distance - reach %g", fs[i], v, o.error, lt - a.reach);
        }
    }
    ak_skeleton_destroy(a.skeleton);
}

/* The same job twice gives the same bits (the saddle escape and the damping use no
 * randomness and no state); so does the same target from a fresh copy of the rest pose. */
AK_TEST(dls_deterministic) {
    straight_arm a;
    if (!straight_arm_make(&a)) {
        AK_CHECK_MSG(false, "the straight arm could not be built");
        ak_skeleton_destroy(a.skeleton);
        return;
    }
    const ak_vec3 targets[3] = {straight_arm_point(&a, 0.95), ak_vec3_make(0.552754f, 1.057246f, 1e-5f),
                                ak_vec3_make(0.3f, 1.1f, 0.2f)};
    for (int k = 0; k < 3; ++k) {
        ak_transform p0[4], p1[4];
        memcpy(p0, a.rest, sizeof p0);
        memcpy(p1, a.rest, sizeof p1);
        solve_out o0 = solve(a.skeleton, p0, a.chain, 3, targets[k], AK_IK_SOLVER_DLS, NULL);
        solve_out o1 = solve(a.skeleton, p1, a.chain, 3, targets[k], AK_IK_SOLVER_DLS, NULL);
        AK_CHECK(memcmp(p0, p1, sizeof p0) == 0);
        AK_CHECK(memcmp(&o0.error, &o1.error, sizeof o0.error) == 0 && o0.iterations == o1.iterations);
    }
    ak_skeleton_destroy(a.skeleton);
}

int main(void) {
    AK_RUN(chain_build);
    AK_RUN(solver_names);
    AK_RUN(chain_job_validity);
    AK_RUN(two_bone_job_validity);
    AK_RUN(ccd_hand_computed_planar);
    AK_RUN(ccd_options);
    AK_RUN(reach_free_3d);
    AK_RUN(reach_planar_hinges);
    AK_RUN(limits_never_violated);
    AK_RUN(animated_translation_kept);
    AK_RUN(two_bone_closed_form_and_pole);
    AK_RUN(two_bone_bend_side_mid_axis);
    AK_RUN(two_bone_chain_matches_job_and_limits);
    AK_RUN(two_bone_soft_weight_unreachable);
    AK_RUN(two_bone_run_many_equals_single_jobs);
    AK_RUN(unreachable_straightens);
    AK_RUN(degenerate_chains);
    AK_RUN(straight_chain_targets_on_its_line);
    AK_RUN(extreme_scales);
    AK_RUN(dls_orientation_target);
    AK_RUN(dls_straight_arm_issue_case);
    AK_RUN(dls_straight_arm_near_its_line);
    AK_RUN(ccd_fabrik_straight_arm_near_its_line);
    AK_RUN(dls_nearly_straight_arm);
    AK_RUN(dls_straight_free_chain_near_its_line);
    AK_RUN(dls_straight_arm_unreachable);
    AK_RUN(dls_deterministic);
    AK_RUN(fabrik_tree);
    return ak_test_finish();
}
