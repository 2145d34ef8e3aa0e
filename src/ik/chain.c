/* IK chains: building and checking chains, the chain job (validation, defaults, dispatch to
 * the solvers in ccd.c, fabrik.c, dls.c, two_bone.c). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "ik_internal.h"

#define AK_IK_DEFAULT_ITERATIONS 50u

/* ---- helpers ------------------------------------------------------------------------- */

/* Model transform of joint j's parent (identity for a root): walk up, composing on the left. */
static ak_transform parent_model(const ak_skeleton* sk, const ak_transform* pose, int j) {
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_transform acc = ak_transform_identity();
    for (int p = parents.ptr[j]; p >= 0; p = parents.ptr[p]) acc = ak_transform_mul(pose[p], acc);
    return acc;
}

/* Index and hierarchy checks of a chain. */
static ak_result check_chain(const ak_skeleton* sk, ak_i16_cspan chain) {
    const size_t n = ak_skeleton_joint_count(sk);
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    for (size_t k = 0; k < chain.count; ++k)
        if (chain.ptr[k] < 0 || (size_t)chain.ptr[k] >= n) return AK_ERR_BAD_INDEX;
    for (size_t k = 1; k < chain.count; ++k)
        if (parents.ptr[chain.ptr[k]] != chain.ptr[k - 1]) return AK_ERR_BAD_HIERARCHY;
    return AK_OK;
}

/* Largest absolute scale component of a transform, in double. */
static double max_scale(const ak_transform* t) {
    return fmax(fabs((double)t->scale.x), fmax(fabs((double)t->scale.y), fabs((double)t->scale.z)));
}

/* |translation|_1 of a transform, in double. */
static double translation_l1(const ak_transform* t) {
    return fabs((double)t->translation.x) + fabs((double)t->translation.y) + fabs((double)t->translation.z);
}

/* Every transform of the chain and its ancestors is finite, and so are their model-space
 * transforms: float FK of finite locals can still overflow (bones of 3e38 end to end). The
 * model translations are bounded, in double, by sum_k |t_k|_1 prod_{j<k} max|s_j|
 * (rotations keep lengths); only when that passes 1e30 does the exact float FK decide. */
static bool pose_chain_finite(const ak_skeleton* sk, const ak_transform* pose, ak_i16_cspan chain) {
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    double bound = 0.0, scale = 1.0;
    for (size_t k = chain.count; k-- > 0;) { /* bottom-up: the chain, then its ancestors */
        const ak_transform* t = &pose[chain.ptr[k]];
        if (!ak_transform_is_finite(*t)) return false;
        bound = bound * max_scale(t) + translation_l1(t);
    }
    for (int p = parents.ptr[chain.ptr[0]]; p >= 0; p = parents.ptr[p]) {
        const ak_transform* t = &pose[p];
        if (!ak_transform_is_finite(*t)) return false;
        bound = bound * max_scale(t) + translation_l1(t);
        scale *= max_scale(t);
    }
    if (bound < 1e30 && scale < 1e30) return true;
    ak_transform w = parent_model(sk, pose, chain.ptr[0]);
    if (!ak_transform_is_finite(w)) return false;
    for (size_t k = 0; k < chain.count; ++k) {
        w = ak_transform_mul(w, pose[chain.ptr[k]]);
        if (!ak_transform_is_finite(w)) return false;
    }
    return true;
}

/* Sum of bone lengths from already computed world transforms. */
static float world_length(const ak_transform* world, size_t count) {
    float len = 0.0f;
    for (size_t i = 1; i < count; ++i) len += ak_vec3_distance(world[i].translation, world[i - 1].translation);
    return len;
}

static bool nonneg(float x) { return x >= 0.0f && ak_finitef(x); }

/* |a - b| in double: neither overflows nor underflows for any finite floats. */
static double distance_d(ak_vec3 a, ak_vec3 b) {
    const double x = (double)a.x - b.x, y = (double)a.y - b.y, z = (double)a.z - b.z;
    return sqrt(x * x + y * y + z * z);
}

static void* align16(void* p) { return (void*)(((uintptr_t)p + 15u) & ~(uintptr_t)15u); }

static size_t world_bytes(size_t n) { return akp_align16(n * sizeof(ak_transform)); }

/* ---- chains -------------------------------------------------------------------------- */

ak_result ak_ik_chain_build(const ak_skeleton* skeleton, int root_joint, int effector_joint, ak_i16_span out_joints,
                            size_t* out_count) {
    if (!skeleton || !out_count) return AK_ERR_NULL_ARG;
    const size_t n = ak_skeleton_joint_count(skeleton);
    if (root_joint < 0 || effector_joint < 0 || (size_t)root_joint >= n || (size_t)effector_joint >= n)
        return AK_ERR_BAD_INDEX;
    ak_i32_cspan parents = ak_skeleton_parents(skeleton);
    size_t count = 1;
    int j = effector_joint;
    while (j != root_joint) {
        j = parents.ptr[j];
        if (j < 0) return AK_ERR_NOT_FOUND;
        ++count;
    }
    *out_count = count;
    if (!out_joints.ptr) return AK_ERR_NULL_ARG;
    if (out_joints.count < count) return AK_ERR_SPAN_SMALL;
    if (effector_joint > INT16_MAX) return AK_ERR_UNSUPPORTED; /* chains hold int16 joint indices */
    j = effector_joint;
    for (size_t k = count; k-- > 0;) {
        out_joints.ptr[k] = (int16_t)j;
        j = parents.ptr[j];
    }
    return AK_OK;
}

ak_result ak_ik_chain_positions(const ak_skeleton* skeleton, ak_transform_cspan pose, ak_i16_cspan chain,
                                ak_vec3_span out_positions) {
    if (!skeleton || !pose.ptr || !chain.ptr || !out_positions.ptr || chain.count == 0) return AK_ERR_NULL_ARG;
    if (pose.count < ak_skeleton_joint_count(skeleton) || out_positions.count < chain.count)
        return AK_ERR_SPAN_SMALL;
    ak_result r = check_chain(skeleton, chain);
    if (r != AK_OK) return r;
    ak_transform w = parent_model(skeleton, pose.ptr, chain.ptr[0]);
    for (size_t k = 0; k < chain.count; ++k) {
        w = ak_transform_mul(w, pose.ptr[chain.ptr[k]]);
        out_positions.ptr[k] = w.translation;
    }
    return AK_OK;
}

float ak_ik_chain_length(const ak_skeleton* skeleton, ak_transform_cspan pose, ak_i16_cspan chain) {
    if (!skeleton || !pose.ptr || !chain.ptr || chain.count == 0) return 0.0f;
    if (pose.count < ak_skeleton_joint_count(skeleton) || check_chain(skeleton, chain) != AK_OK) return 0.0f;
    ak_transform w = parent_model(skeleton, pose.ptr, chain.ptr[0]);
    double len = 0.0; /* in double: a float squared distance overflows from bones of ~1e19 */
    ak_vec3 prev = ak_vec3_zero();
    for (size_t k = 0; k < chain.count; ++k) {
        w = ak_transform_mul(w, pose.ptr[chain.ptr[k]]);
        if (k > 0) len += distance_d(w.translation, prev);
        prev = w.translation;
    }
    return len < FLT_MAX ? (float)len : (len == len ? FLT_MAX : 0.0f);
}

/* ---- solver names ---------------------------------------------------------------------- */

static const char* const solver_names[AK_IK_SOLVER_COUNT] = {"default", "ccd", "fabrik", "twobone", "dls"};

const char* ak_ik_solver_name(ak_ik_solver solver) {
    if ((int)solver < 0 || solver >= AK_IK_SOLVER_COUNT) return "";
    return solver_names[solver];
}

ak_result ak_ik_solver_parse(const char* name, ak_ik_solver* out_solver) {
    if (!name || !out_solver) return AK_ERR_NULL_ARG;
    for (int s = 0; s < AK_IK_SOLVER_COUNT; ++s) {
        if (strcmp(name, solver_names[s]) == 0) {
            *out_solver = (ak_ik_solver)s;
            return AK_OK;
        }
    }
    if (strcmp(name, "two_bone") == 0 || strcmp(name, "two-bone") == 0) {
        *out_solver = AK_IK_SOLVER_TWO_BONE;
        return AK_OK;
    }
    return AK_ERR_NOT_FOUND;
}

/* ---- the chain job --------------------------------------------------------------------- */

static ak_ik_solver resolve_solver(ak_ik_solver s) { return s == AK_IK_SOLVER_DEFAULT ? AK_IK_SOLVER_FABRIK : s; }

size_t ak_ik_chain_scratch_size(ak_ik_solver solver, size_t chain_count) {
    size_t n = chain_count ? chain_count : 1;
    /* 16: room to align the caller's pointer */
    size_t bytes = 16 + 2 * world_bytes(n) + 2 * akp_align16(n);
    switch (resolve_solver(solver)) {
    case AK_IK_SOLVER_FABRIK: bytes += 2 * akp_align16(n * sizeof(ak_vec3)) + akp_align16(n * sizeof(float)); break;
    case AK_IK_SOLVER_DLS: bytes += akp_ik_dls_scratch_size(n); break;
    default: break;
    }
    return bytes;
}

ak_ik_chain_job ak_ik_chain_job_resolved(const ak_ik_chain_job* job) {
    ak_ik_chain_job r;
    memset(&r, 0, sizeof r);
    if (!job) return r;
    r = *job;
    r.solver = resolve_solver(r.solver);
    if (r.max_iterations == 0) r.max_iterations = AK_IK_DEFAULT_ITERATIONS;
    if (r.angle_tolerance == 0.0f) r.angle_tolerance = 1e-3f;
    if (r.max_step == 0.0f) r.max_step = AK_PI;
    float len = ak_ik_chain_length(job->skeleton, (ak_transform_cspan){job->pose.ptr, job->pose.count}, job->chain);
    if (job->skeleton && job->pose.ptr && job->chain.ptr && job->chain.count) {
        /* Relative to the chain's length, whatever its scale; fixed values only for a chain
         * of zero length. */
        if (r.tolerance == 0.0f) r.tolerance = len > 0.0f ? 1e-4f * len : 1e-7f;
        if (r.dls_damping == 0.0f) r.dls_damping = len > 0.0f ? 0.1f * len : 1e-6f;
        if (r.orientation_weight == 0.0f) r.orientation_weight = len > 0.0f ? len / AK_PI : 1e-6f;
    }
    return r;
}

ak_result ak_ik_chain_validate(const ak_ik_chain_job* job) {
    if (!job || !job->skeleton || !job->pose.ptr || !job->chain.ptr || job->chain.count == 0) return AK_ERR_NULL_ARG;
    if (job->pose.count < ak_skeleton_joint_count(job->skeleton)) return AK_ERR_SPAN_SMALL;
    if ((int)job->solver < 0 || job->solver >= AK_IK_SOLVER_COUNT) return AK_ERR_BAD_ARG;
    ak_result r = check_chain(job->skeleton, job->chain);
    if (r != AK_OK) return r;
    if (job->solver == AK_IK_SOLVER_TWO_BONE && job->chain.count != 3) return AK_ERR_BAD_ARG;
    if (!ak_vec3_is_finite(job->target) || !ak_vec3_is_finite(job->pole)) return AK_ERR_BAD_DATA;
    if (job->target_rotation) {
        ak_quat q = *job->target_rotation;
        if (!ak_quat_is_finite(q) || !(ak_quat_dot(q, q) > 1e-12f)) return AK_ERR_BAD_DATA;
    }
    if (!nonneg(job->tolerance) || !nonneg(job->angle_tolerance) || !nonneg(job->max_step) ||
        !nonneg(job->dls_damping) || !nonneg(job->orientation_weight))
        return AK_ERR_BAD_ARG;
    if (!(job->soft >= 0.0f && job->soft < 1.0f)) return AK_ERR_BAD_ARG;
    if (!(job->keep_animation >= 0.0f && job->keep_animation <= 1.0f)) return AK_ERR_BAD_ARG;
    if (!pose_chain_finite(job->skeleton, job->pose.ptr, job->chain)) return AK_ERR_BAD_DATA;
    if (!job->scratch.ptr) return AK_ERR_NULL_ARG;
    if (job->scratch.count < ak_ik_chain_scratch_size(job->solver, job->chain.count)) return AK_ERR_SPAN_SMALL;
    return AK_OK;
}

/* Give the effector the target rotation (then its limits), for the solvers that place only
 * positions. */
static void apply_target_rotation(akp_ik_chain* c, const ak_quat* target_rotation) {
    if (!target_rotation) return;
    const size_t last = c->count - 1, j = (size_t)c->joints[last];
    akp_ik_set_world_rot(c, last, ak_quat_normalize(*target_rotation));
    if (c->types[last] != AK_JOINT_FREE && !c->clamp[last]) { /* an arbitrary turn: clamp anyway */
        c->pose[j] = akp_ik_limit(c->skeleton, j, c->pose[j]);
        c->world[last] = akp_ik_compose(akp_ik_parent_world(c, last), c->pose[j]);
    }
}

/* Direction (+1, -1) in which a hinge joint may bend from where it is, preferring
 * `preferred` when its limits leave at least 1e-3 rad that way, and the room left that way
 * (radians, INFINITY when unlimited); 0 when neither way has room. */
static float hinge_bend_sign(const akp_ik_chain* c, size_t i, float preferred, float* out_room) {
    const size_t j = (size_t)c->joints[i];
    const ak_joint_limits l = ak_skeleton_joint_limits(c->skeleton, j);
    *out_room = INFINITY;
    if (!c->clamp[i] || (l.min == 0.0f && l.max == 0.0f)) return preferred;
    const float a = akp_ik_hinge_angle(c->skeleton, j, c->pose[j].rotation);
    const float up = l.max - a, down = a - l.min, need = 1e-3f;
    if ((preferred > 0.0f ? up : down) >= need) {
        *out_room = preferred > 0.0f ? up : down;
        return preferred;
    }
    if ((preferred > 0.0f ? down : up) >= need) {
        *out_room = preferred > 0.0f ? down : up;
        return -preferred;
    }
    *out_room = 0.0f;
    return 0.0f;
}

/* World axis of chain joint i's hinge. */
static ak_vec3 hinge_world_axis(const akp_ik_chain* c, size_t i) {
    return ak_vec3_normalize(ak_quat_rotate(c->world[i].rotation, ak_skeleton_joint_limits(c->skeleton, (size_t)c->joints[i]).axis));
}

/* How chain joint i (below the root) bends in the plane of `normal`: the turn's sign about
 * its own axis (0: it does not bend) and the room its limits leave (radians). */
static float bend_sign(const akp_ik_chain* c, size_t i, ak_vec3 normal, float* out_room) {
    *out_room = INFINITY;
    if (c->types[i] == AK_JOINT_PRISM) return 0.0f;
    if (c->types[i] != AK_JOINT_HINGE) return 1.0f;
    return hinge_bend_sign(c, i, ak_vec3_dot(hinge_world_axis(c, i), normal) < 0.0f ? -1.0f : 1.0f, out_room);
}

/* Distance from the root to the effector of the straight chain (bones lengths[k] from
 * chain joint k to k + 1) once every bending joint below the root turns by beta in one
 * plane: |sum_k length_k e^(i theta_k)|, theta_k = beta x (bending joints among 1..k). */
static float curled_chord(const akp_ik_chain* c, ak_vec3 normal, float beta) {
    float x = 0.0f, y = 0.0f, theta = 0.0f, room;
    for (size_t k = 0; k + 1 < c->count; ++k) {
        if (k > 0 && bend_sign(c, k, normal, &room) != 0.0f) theta += beta;
        const float len = ak_vec3_distance(c->world[k + 1].translation, c->world[k].translation);
        x += len * cosf(theta);
        y += len * sinf(theta);
    }
    return sqrtf(x * x + y * y);
}

/* A straight chain whose line passes through the target is a singular configuration for the
 * iterative solvers: CCD's RE is parallel to RD at every joint, the Jacobian has no column
 * along the line, and FABRIK's passes stay on the line. Bend the chain in one plane before
 * iterating: the plane's normal is the axis of the first hinge below the root (turned to
 * the side its limits allow), else the root's hinge axis, else a fixed normal of the line
 * (ak_vec3_any_perpendicular). Every joint below the root (prism joints excepted) turns by
 * the same angle beta about that normal (a hinge about its own axis, on the side its limits
 * allow), beta chosen by bisection so that the curled chain's chord equals the target's
 * distance (at most 3 rad, 2 pi / bones, and what the hinges' limits leave); then the root
 * turns the effector back onto the line towards the target. In one plane this reaches the
 * target at once; the solvers finish what limits or off-plane axes leave. The chain curls
 * like a limb flexing its hinges, the side the solvers keep (a hinge bent the other way
 * would be clamped straight again). */
bool akp_ik_unstraighten(akp_ik_chain* c, bool off_line) {
    const size_t last = c->count - 1;
    const ak_vec3 root = c->world[0].translation;
    const ak_vec3 dir = ak_vec3_normalize(ak_vec3_sub(c->world[last].translation, root));
    if (ak_vec3_length_sq(dir) == 0.0f || !(c->length > 0.0f)) return false;
    const float eps = 1e-5f * c->length;
    /* Off the line (DLS): nearly straight counts too, joints within 1e-3 of the length of the
     * line (a bend of ~4e-3 rad): there the first-order gain of a step along the line is
     * below what float positions resolve, so the Jacobian stalls as on the straight line. */
    const float straight_eps = off_line ? 1e-3f * c->length : eps;
    for (size_t i = 1; i <= last; ++i) {
        ak_vec3 d = ak_vec3_sub(c->world[i].translation, root);
        if (ak_vec3_length(ak_vec3_madd(d, dir, -ak_vec3_dot(d, dir))) > straight_eps) return false; /* not straight */
    }
    const ak_vec3 dt = ak_vec3_sub(c->target, root);
    if (off_line) {
        if (ak_vec3_length(dt) >= c->length - eps) return false; /* beyond the reach: straight is the answer */
    } else {
        if (ak_vec3_length(ak_vec3_madd(dt, dir, -ak_vec3_dot(dt, dir))) > eps) return false; /* target off the line */
        if (ak_vec3_dot(dt, dir) >= c->length - eps) return false; /* beyond the reach: straight is the answer */
    }
    /* The bend plane's normal: a hinge's axis (on its allowed side) fixes the plane the chain
     * can bend in; without hinges any normal of the line does. */
    ak_vec3 normal = ak_vec3_zero();
    float room;
    for (size_t k = 0; k < last && ak_vec3_length_sq(normal) == 0.0f; ++k) {
        const size_t i = k + 1 < last ? k + 1 : 0; /* joints below the root first, then the root */
        if (c->types[i] != AK_JOINT_HINGE) continue;
        const ak_vec3 w = hinge_world_axis(c, i);
        const ak_vec3 n = ak_vec3_madd(w, dir, -ak_vec3_dot(w, dir));
        if (ak_vec3_length_sq(n) < 1e-6f) continue; /* turns about the line itself: no bend */
        const float sign = i == 0 ? 1.0f : hinge_bend_sign(c, i, 1.0f, &room);
        if (sign != 0.0f) normal = ak_vec3_scale(ak_vec3_normalize(n), sign);
    }
    if (ak_vec3_length_sq(normal) == 0.0f) normal = ak_vec3_any_perpendicular(dir);
    /* The largest common turn: 3 rad, the first zero of a regular curl's chord (2 pi over
     * the bones), and the room of every limited hinge. */
    float hi = ak_minf(3.0f, 2.0f * AK_PI / (float)last);
    size_t bending = 0;
    for (size_t i = 1; i < last; ++i) {
        if (bend_sign(c, i, normal, &room) == 0.0f) continue;
        ++bending;
        hi = ak_minf(hi, room);
    }
    if (bending == 0) return false; /* nothing below the root can bend */
    const float d = ak_vec3_length(dt);
    float lo = 0.0f, beta = hi;
    if (curled_chord(c, normal, hi) < d) {
        for (int it = 0; it < 32; ++it) { /* chord(lo) > d >= chord(beta) */
            const float mid = 0.5f * (lo + beta);
            if (curled_chord(c, normal, mid) > d) lo = mid;
            else beta = mid;
        }
    }
    for (size_t i = 1; i < last; ++i) {
        const float sign = bend_sign(c, i, normal, &room);
        if (sign == 0.0f) continue;
        const ak_vec3 axis = c->types[i] == AK_JOINT_HINGE ? hinge_world_axis(c, i) : normal;
        akp_ik_rotate(c, i, ak_quat_from_axis_angle(axis, sign * beta));
        akp_ik_fk(c, i + 1);
    }
    if (c->types[0] != AK_JOINT_PRISM) {
        const bool hinge = c->types[0] == AK_JOINT_HINGE;
        const ak_vec3 axis = hinge ? hinge_world_axis(c, 0) : ak_vec3_zero();
        akp_ik_rotate(c, 0, akp_ik_aim_rotation(ak_vec3_sub(c->world[last].translation, root), dt, hinge, axis, AK_PI));
        akp_ik_fk(c, 1);
    }
    akp_ik_track_best(c, ak_vec3_distance(c->world[last].translation, c->target));
    return true;
}

ak_result ak_ik_chain_run(const ak_ik_chain_job* job) {
    ak_result res = ak_ik_chain_validate(job);
    if (res != AK_OK) return res;
    const ak_ik_chain_job rj = ak_ik_chain_job_resolved(job);
    const size_t n = rj.chain.count;

    unsigned char* mem = (unsigned char*)align16(rj.scratch.ptr);
    akp_ik_chain c;
    c.skeleton = rj.skeleton;
    c.pose = rj.pose.ptr;
    c.joints = rj.chain.ptr;
    c.count = n;
    c.base = parent_model(rj.skeleton, rj.pose.ptr, rj.chain.ptr[0]);
    c.world = (ak_transform*)mem;
    mem += world_bytes(n);
    c.best = (ak_transform*)mem;
    mem += world_bytes(n);
    c.types = mem;
    mem += akp_align16(n);
    c.clamp = mem;
    mem += akp_align16(n);
    for (size_t i = 0; i < n; ++i) {
        const size_t j = (size_t)rj.chain.ptr[i];
        const ak_joint_type type = rj.ignore_limits ? AK_JOINT_FREE : ak_skeleton_joint_type(rj.skeleton, j);
        const ak_joint_limits l = ak_skeleton_joint_limits(rj.skeleton, j);
        c.types[i] = (uint8_t)type;
        c.clamp[i] = (uint8_t)(type == AK_JOINT_PRISM ||
                               (type == AK_JOINT_HINGE && (l.min != 0.0f || l.max != 0.0f)) ||
                               (type == AK_JOINT_BALL && (l.cone_angle > 0.0f || l.twist_min != 0.0f || l.twist_max != 0.0f)));
    }
    c.limits = !rj.ignore_limits;
    /* Outside common sizes, solve in a frame centred on the chain root and scaled by a power
     * of two S that brings the chain's extent into [0.5, 1): squared distances can neither
     * overflow (bones of 1e30) nor vanish under the solvers' fixed thresholds (bones of
     * 1e-30), and scaling by a power of two is exact. Only the chain's base moves into the
     * frame (its translation shifted, its scale divided by S), so local rotations and prism
     * slides come out in the pose's own units. A target farther than 1e6 chain extents is
     * moved onto the same ray from the root at that distance (out of reach either way). */
    akp_ik_fk(&c, 0);
    const ak_vec3 root = c.world[0].translation;
    const double tx = (double)rj.target.x - root.x, ty = (double)rj.target.y - root.y, tz = (double)rj.target.z - root.z;
    const double target_distance = sqrt(tx * tx + ty * ty + tz * tz);
    double scale = 1.0, inv = 1.0;
    c.target = rj.target;
    c.length = world_length(c.world, n); /* inf or 0 when squares overflow or vanish */
    /* Common sizes (a chain between 1e-3 and 1e6 units long, a target within 1e9 of its
     * root) are solved as they are: every product of squared lengths stays far inside float. */
    const bool common = c.length >= 0x1p-10f && c.length <= 0x1p20f && target_distance <= 0x1p30;
    if (!common) {
        double extent = 0.0;
        for (size_t i = 1; i < n; ++i) {
            const ak_vec3 p = c.world[i].translation;
            extent = fmax(extent, fmax(fabs((double)p.x - root.x), fmax(fabs((double)p.y - root.y), fabs((double)p.z - root.z))));
        }
        int exponent = 0;
        if (extent > 0.0) frexp(extent, &exponent);
        scale = ldexp(1.0, exponent), inv = 1.0 / scale;
        /* The same affine map on the base and on the world transforms already computed: what
         * FK from the moved base gives, without running it again. */
        for (size_t i = 0; i <= n; ++i) {
            ak_transform* w = i == 0 ? &c.base : &c.world[i - 1];
            w->translation = ak_vec3_make((float)(((double)w->translation.x - root.x) * inv),
                                          (float)(((double)w->translation.y - root.y) * inv),
                                          (float)(((double)w->translation.z - root.z) * inv));
            w->scale = ak_vec3_make((float)(w->scale.x * inv), (float)(w->scale.y * inv), (float)(w->scale.z * inv));
        }
        const double far = 1e6, k = target_distance * inv > far ? far / (target_distance * inv) : 1.0;
        c.target = ak_vec3_make((float)(tx * inv * k), (float)(ty * inv * k), (float)(tz * inv * k));
        c.length = world_length(c.world, n);
    }
    c.tolerance = (float)(rj.tolerance * inv);
    ak_ik_chain_job sj = rj; /* the job's lengths in the solve's frame */
    sj.tolerance = c.tolerance;
    sj.dls_damping = (float)(rj.dls_damping * inv);
    sj.orientation_weight = (float)(rj.orientation_weight * inv);
    c.best_error = INFINITY;
    akp_ik_track_best(&c, ak_vec3_distance(c.world[n - 1].translation, c.target));

    akp_ik_outcome out = {0.0f, 0};
    if (n == 1) {
        /* Nothing can move the root's own position. */
        apply_target_rotation(&c, rj.target_rotation);
    } else {
        const float start_error = ak_vec3_distance(c.world[n - 1].translation, c.target);
        /* DLS curls a straight chain itself, for targets off the line too (dls.c). */
        if (rj.solver != AK_IK_SOLVER_TWO_BONE && rj.solver != AK_IK_SOLVER_DLS && start_error > c.tolerance)
            akp_ik_unstraighten(&c, false);
        switch (rj.solver) {
        case AK_IK_SOLVER_CCD:
            out = akp_ik_ccd(&c, &sj);
            apply_target_rotation(&c, rj.target_rotation);
            break;
        case AK_IK_SOLVER_TWO_BONE:
            akp_ik_two_bone_chain(&c, &sj);
            apply_target_rotation(&c, rj.target_rotation);
            break;
        case AK_IK_SOLVER_DLS: out = akp_ik_dls(&c, &sj, mem); break;
        case AK_IK_SOLVER_FABRIK:
        default: {
            ak_vec3* pos = (ak_vec3*)mem;
            ak_vec3* prev = (ak_vec3*)(mem + akp_align16(n * sizeof(ak_vec3)));
            float* len = (float*)(mem + 2 * akp_align16(n * sizeof(ak_vec3)));
            out = akp_ik_fabrik(&c, &sj, pos, prev, len);
            apply_target_rotation(&c, rj.target_rotation);
            break;
        }
        }
    }
    /* The error in model units, in double: the effector back out of the solve's frame. */
    const ak_vec3 e = c.world[n - 1].translation;
    const ak_vec3 shift = common ? ak_vec3_zero() : root;
    const double ex = (double)e.x * scale + shift.x - rj.target.x, ey = (double)e.y * scale + shift.y - rj.target.y,
                 ez = (double)e.z * scale + shift.z - rj.target.z;
    const double error_d = sqrt(ex * ex + ey * ey + ez * ez);
    const float error = error_d < FLT_MAX ? (float)error_d : FLT_MAX;
    float angle_error = 0.0f;
    if (rj.target_rotation) {
        ak_quat d = ak_quat_mul(ak_quat_normalize(*rj.target_rotation), ak_quat_conjugate(c.world[n - 1].rotation));
        angle_error = akp_quat_angle(d);
    }
    if (job->out_reached)
        *job->out_reached = error_d <= rj.tolerance && (!rj.target_rotation || angle_error <= rj.angle_tolerance);
    if (job->out_error) *job->out_error = error;
    if (job->out_angle_error) *job->out_angle_error = angle_error;
    if (job->out_iterations) *job->out_iterations = out.iterations;
    return AK_OK;
}
