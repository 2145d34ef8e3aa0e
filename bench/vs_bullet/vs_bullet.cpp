// bench/vs_bullet: animkit's rigid bodies (XPBD, animkit/rigid.h) beside Bullet 3 (Debian's
// libbullet-dev, btDiscreteDynamicsWorld with its sequential-impulse solver), in one process
// on the same scenes with matched settings: a 2D pyramid of unit boxes on the ground, spheres
// dropped as a block into an open box, and ragdolls of builtin:humanoid dropped on the ground.
// Prints time per step for both (CPU time of the calling thread, so that other processes on a
// shared machine count less), the ratio, and the stability of each (the largest horizontal
// drift of a body from its start, or for ragdolls the widest joint gap; the deepest penetration
// seen). One thread (animkit: --threads T sets its thread_count, and its time is then wall
// time; the final state's hash is printed to compare thread counts, and a second line gives
// animkit's CPU time per step on the calling thread and on all threads, with the share of the
// latter spent off the calling thread, by the worker team); sleeping on in both, each at its
// own thresholds (--sleep: see sleep_mode); dt = 1/60; friction 0.5; density 1000.
//
//   bench_rigid_vs_bullet [--layers L] [--spheres N] [--ragdolls R] [--steps S] [--substeps K]
//                         [--threads T] [--only pyramid|spheres|ragdolls] [--sleep own|bullet|off]
//                         [--contacts-after-joints] [--contact-iterations K]
//                         [--sweep [--rounds R] [--ak-substeps 2,3,4,6,10] [--ak-iterations 1]
//                                  [--ak-ref 10]
//                                  [--bt-iterations 10,20,50] [--bt-substeps 1,2,4]]
//
// --sweep compares at matched stability instead: per scene, animkit at each substep count of
// --ak-substeps and Bullet at each of --bt-iterations x --bt-substeps (a step of dt taken as that
// many fixed substeps), R rounds interleaved, with the stability measured after every step (the
// largest drift, penetration, joint gap and joint-limit excess over the whole run, both engines'
// poses measured by the same code); then the cheapest animkit setting as stable as Bullet's
// defaults on every measure and the cheapest Bullet setting as stable as animkit at --ak-ref
// substeps, with their time ratios.
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <algorithm>
#include <vector>

#include <animkit/builtin.h>
#include <animkit/rigid.h>
#include <animkit/scene.h>
#include <animkit/skeleton.h>

#include "bench_clock.h"

struct result {
    double ms_per_step;
    double cpu_ms, proc_ms, wall_ms;  // animkit: per step, CPU of the calling thread, of all threads, wall
    double drift;  // m, largest horizontal displacement of a body from its start
    double pen;    // m, deepest penetration seen over the run
    double contacts;  // contact points per step, mean over the run
    uint64_t hash;    // animkit: FNV-1a of the final state
    uint64_t dropped = 0;  // animkit: contact points (and pairs) over max_contacts, whole run
    int drop_steps = 0, drop_first = -1;  // steps that dropped any, the first of them
    // --sweep only, sampled after every step (the probes' time is left out of ms_per_step and
    // cpu_ms): the largest horizontal drift of a body from its start (scenes without joints),
    // the widest joint gap (m) and the largest joint-limit excess (rad) over all steps, and the
    // bodies found more than 5 cm behind a plane (through the ground or a wall) at any step
    double drift_max = 0, gap_max = 0, limit_max = 0;
    int escaped = 0;
};

struct scene {
    std::vector<ak_rigid_body_desc> bodies;  // the first `planes` are static planes
    size_t planes = 0;
    std::vector<ak_rigid_joint_desc> joints;  // ragdolls: `drift` is then the widest joint gap
};

// The --sweep probe of one state (x, q: every body's pose, planes included): see result.
// Both engines' states go through it, Bullet's poses copied in (a capsule is along local Y in
// both and its centre of mass is the body origin), so each measure is the same code for both;
// m is a model of the scene (its joints' local anchors and limits).
static void probe(const scene& sc, const ak_rigid_model* m, const std::vector<ak_vec3>& x,
                  const std::vector<ak_quat>& q, result* r) {
    const size_t n = x.size();
    int behind = 0;
    for (size_t i = sc.planes; i < n; ++i) {
        if (sc.joints.empty())
            r->drift_max =
                std::fmax(r->drift_max, std::hypot((double)(x[i].x - sc.bodies[i].position.x),
                                                   (double)(x[i].z - sc.bodies[i].position.z)));
        for (size_t k = 0; k < sc.planes; ++k) {
            const ak_vec3 nr = sc.bodies[k].shape.normal, p = sc.bodies[k].position;
            if (nr.x * (x[i].x - p.x) + nr.y * (x[i].y - p.y) + nr.z * (x[i].z - p.z) < -0.05f) {
                ++behind;
                break;
            }
        }
    }
    r->escaped = std::max(r->escaped, behind);
    for (size_t k = 0; k < sc.joints.size(); ++k) {
        float gap = 0.0f, excess = 0.0f;
        ak_rigid_joint_error(m, k, {x.data(), n}, {q.data(), n}, &gap, &excess);
        r->gap_max = std::fmax(r->gap_max, (double)gap);
        r->limit_max = std::fmax(r->limit_max, (double)excess);
    }
}

static ak_rigid_body_desc zero_body() {
    ak_rigid_body_desc b;
    std::memset(&b, 0, sizeof b);
    return b;
}

static scene pyramid(int layers) {
    scene s;
    ak_rigid_body_desc g = zero_body();
    g.shape.type = AK_RIGID_PLANE;
    g.shape.normal = ak_vec3_make(0, 1, 0);
    s.bodies.push_back(g);
    s.planes = 1;
    for (int l = 0; l < layers; ++l)
        for (int i = 0; i < layers - l; ++i) {
            ak_rigid_body_desc b = zero_body();
            b.shape.type = AK_RIGID_BOX;
            b.shape.half_extents = ak_vec3_make(0.5f, 0.5f, 0.5f);
            b.position = ak_vec3_make(1.1f * ((float)i - 0.5f * (float)(layers - l - 1)), 0.5f + (float)l, 0.0f);
            s.bodies.push_back(b);
        }
    return s;
}

// n spheres of radius 0.1 in a lattice 0.25 m apart (15 x 15 per layer) above an open 4 x 4 m
// box: the ground and four walls
static scene spheres(int n) {
    scene s;
    const ak_vec3 normals[5] = {{0, 1, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1}};
    const ak_vec3 points[5] = {{0, 0, 0}, {-2, 0, 0}, {2, 0, 0}, {0, 0, -2}, {0, 0, 2}};
    for (int k = 0; k < 5; ++k) {
        ak_rigid_body_desc g = zero_body();
        g.shape.type = AK_RIGID_PLANE;
        g.shape.normal = normals[k];
        g.position = points[k];
        s.bodies.push_back(g);
    }
    s.planes = 5;
    const int side = 15;
    for (int i = 0; i < n; ++i) {
        ak_rigid_body_desc b = zero_body();
        b.shape.type = AK_RIGID_SPHERE;
        b.shape.radius = 0.1f;
        int x = i % side, z = (i / side) % side, y = i / (side * side);
        b.position = ak_vec3_make(-1.75f + 0.25f * (float)x + 0.01f * (float)(y % 3), 0.3f + 0.25f * (float)y,
                                  -1.75f + 0.25f * (float)z);
        s.bodies.push_back(b);
    }
    return s;
}

// count ragdolls of builtin:humanoid in its rest pose (ak_rigid_ragdoll_build: a capsule per
// bone, ball and hinge joints with the skeleton's limits), on a grid 2.5 m apart, dropped from
// 1 m onto the ground; each ragdoll its own collision group (limbs of one do not collide, two
// ragdolls do)
static bool ragdolls(int count, scene* s) {
    ak_rigid_body_desc g = zero_body();
    g.shape.type = AK_RIGID_PLANE;
    g.shape.normal = ak_vec3_make(0, 1, 0);
    s->bodies.push_back(g);
    s->planes = 1;
    ak_scene* sc = nullptr;
    ak_builtin_desc bd;
    std::memset(&bd, 0, sizeof bd);
    bd.cell_size = 0.1f;
    if (ak_builtin_create("humanoid", &bd, nullptr, &sc) != AK_OK) return false;
    const ak_skeleton* sk = sc->skeleton;
    const size_t n = ak_skeleton_joint_count(sk), nb = ak_rigid_ragdoll_body_count(sk),
                 nj = ak_rigid_ragdoll_joint_count(sk);
    std::vector<ak_transform> pose(n);
    std::vector<ak_rigid_ragdoll_bone> bones(n);
    ak_scene_rest_pose(sc, {pose.data(), n});
    bool ok = true;
    for (int r = 0; r < count && ok; ++r) {
        std::vector<ak_rigid_body_desc> b(nb);
        std::vector<ak_rigid_joint_desc> j(nj);
        ak_rigid_ragdoll_desc rd;
        std::memset(&rd, 0, sizeof rd);
        rd.skeleton = sk;
        rd.local_pose = {pose.data(), n};
        rd.root = ak_mat4_translation(ak_vec3_make(2.5f * (float)(r % 10), 1.0f, 2.5f * (float)(r / 10)));
        rd.body_offset = (uint32_t)s->bodies.size();
        rd.collision_group = (uint32_t)r + 1;
        ok = ak_rigid_ragdoll_build(&rd, {b.data(), nb}, {j.data(), nj}, {bones.data(), n}) == AK_OK;
        s->bodies.insert(s->bodies.end(), b.begin(), b.end());
        s->joints.insert(s->joints.end(), j.begin(), j.end());
    }
    ak_scene_destroy(sc);
    return ok;
}

static bool g_anchors = true; // --no-anchors: animkit without its contact anchor cache

// --sleep: how the two engines put bodies to sleep. "own" (the default): each at its own
// defaults (animkit: under 0.05 m/s and 0.05 rad/s for 0.5 s; Bullet: under 0.8 m/s and 1 rad/s
// for 2 s, btRigidBody's thresholds and gDeactivationTime). "bullet": animkit given Bullet's
// thresholds and time, so both freeze the same motion. "off": neither sleeps (animkit without
// sleep timers, Bullet's bodies DISABLE_DEACTIVATION), so each step's time is the solver's work.
enum sleep_mode { SLEEP_OWN, SLEEP_BULLET, SLEEP_OFF };
static sleep_mode g_sleep = SLEEP_OWN;
static const char* sleep_name() {
    return g_sleep == SLEEP_OFF ? "sleeping off in both"
                                : (g_sleep == SLEEP_BULLET ? "sleeping on, animkit at Bullet's thresholds (0.8 m/s, 1 rad/s, 2 s)"
                                                           : "sleeping on, each engine at its defaults");
}

// --contacts-after-joints: animkit's ak_rigid_model_desc.contacts_after_joints (a single run:
// on; --sweep: each substep count both without and with it, interleaved)
static bool g_after_joints = false;

// --contact-iterations K: animkit's ak_rigid_model_desc.contact_iterations for a single run;
// --sweep takes a list (--ak-iterations 1,3: each substep count at each)
static unsigned g_iterations = 1;

static result run_animkit(const scene& sc, int steps, unsigned substeps, unsigned threads,
                          bool track = false, bool after_joints = g_after_joints,
                          unsigned iterations = g_iterations) {
    const size_t n = sc.bodies.size();
    ak_rigid_model_desc md;
    std::memset(&md, 0, sizeof md);
    md.bodies.ptr = sc.bodies.data();
    md.bodies.count = n;
    md.joints.ptr = sc.joints.data();
    md.joints.count = sc.joints.size();
    md.contacts_after_joints = after_joints;
    md.contact_iterations = iterations;
    if (g_sleep == SLEEP_BULLET) {
        md.sleep_linear_speed = 0.8f;
        md.sleep_angular_speed = 1.0f;
        md.sleep_time = 2.0f;
    }
    ak_rigid_model* m = nullptr;
    result r = {};
    if (ak_rigid_model_create(&md, nullptr, &m) != AK_OK) return r;
    std::vector<ak_vec3> x(n), v(n), w(n);
    std::vector<ak_quat> q(n);
    std::vector<float> timers(n, 0.0f);
    ak_rigid_initial_state(m, {x.data(), n}, {q.data(), n}, {v.data(), n}, {w.data(), n});
    float pen = 0.0f;
    ak_rigid_step_job job;
    std::memset(&job, 0, sizeof job);
    job.model = m;
    job.dt = 1.0f / 60.0f;
    job.substeps = substeps;
    job.thread_count = threads;
    job.gravity = ak_vec3_make(0, -9.81f, 0);
    job.positions = {x.data(), n};
    job.orientations = {q.data(), n};
    job.velocities = {v.data(), n};
    job.angular_velocities = {w.data(), n};
    if (g_sleep != SLEEP_OFF) job.sleep_timers = {timers.data(), n};
    job.out_max_penetration = &pen;
    uint32_t contacts = 0, dropped = 0;
    job.out_contact_count = &contacts;
    job.out_dropped_contacts = &dropped;
    // persistent contacts (ak_rigid_contact_anchor), 4 per body; --no-anchors leaves them out
    std::vector<ak_rigid_contact_anchor> anchors(4 * n + 4);
    uint32_t anchor_count = 0;
    if (g_anchors) {
        job.contact_anchors = {anchors.data(), anchors.size()};
        job.contact_anchor_count = &anchor_count;
    }
    const size_t bytes = ak_rigid_step_scratch_size(&job);
    std::vector<uint8_t> scratch(bytes);
    job.scratch = {scratch.data(), bytes};
    // one thread: CPU time of the calling thread; more: wall time (the workers' time counts)
    const double t0 = threads > 1 ? bench_wall_s() : bench_cpu_s();
    const double c0 = bench_cpu_s(), p0 = bench_proc_s(), w0 = bench_wall_s();
    double in_probe = 0.0; // --sweep: the probes' CPU time, left out of ms_per_step and cpu_ms
    for (int s = 0; s < steps; ++s) {
        ak_rigid_step_run(&job);
        if (track) {
            const double t = bench_cpu_s();
            probe(sc, m, x, q, &r);
            in_probe += bench_cpu_s() - t;
        }
        r.pen = std::fmax(r.pen, (double)pen);
        r.contacts += contacts / (double)steps;
        if (dropped) {
            r.dropped += dropped;
            if (!r.drop_steps++) r.drop_first = s;
        }
    }
    r.ms_per_step = 1e3 * ((threads > 1 ? bench_wall_s() : bench_cpu_s()) - t0 - in_probe) / steps;
    r.cpu_ms = 1e3 * (bench_cpu_s() - c0 - in_probe) / steps;
    r.proc_ms = 1e3 * (bench_proc_s() - p0) / steps;
    r.wall_ms = 1e3 * (bench_wall_s() - w0) / steps;
    // FNV-1a of the final state: the same for every thread count (the solver's determinism)
    uint64_t hash = 1469598103934665603ull;
    auto mix = [&hash](const void* p, size_t bytes) {
        for (size_t i = 0; i < bytes; ++i) hash = (hash ^ ((const unsigned char*)p)[i]) * 1099511628211ull;
    };
    mix(x.data(), n * sizeof(ak_vec3));
    mix(q.data(), n * sizeof(ak_quat));
    mix(v.data(), n * sizeof(ak_vec3));
    mix(w.data(), n * sizeof(ak_vec3));
    r.hash = hash;
    for (size_t i = sc.planes; i < n && sc.joints.empty(); ++i)
        r.drift = std::fmax(r.drift, std::hypot((double)(x[i].x - sc.bodies[i].position.x),
                                                (double)(x[i].z - sc.bodies[i].position.z)));
    for (size_t k = 0; k < sc.joints.size(); ++k) {
        float gap = 0.0f, excess = 0.0f;
        ak_rigid_joint_error(m, k, {x.data(), n}, {q.data(), n}, &gap, &excess);
        r.drift = std::fmax(r.drift, (double)gap);
    }
    ak_rigid_model_destroy(m);
    return r;
}

// Bullet's side of collision groups: bodies whose user index (the group) is the same nonzero
// value do not collide, as animkit's collision_group
struct group_filter : public btOverlapFilterCallback {
    bool needBroadphaseCollision(btBroadphaseProxy* p0, btBroadphaseProxy* p1) const override {
        if (!(p0->m_collisionFilterGroup & p1->m_collisionFilterMask) ||
            !(p1->m_collisionFilterGroup & p0->m_collisionFilterMask))
            return false;
        const btCollisionObject* a = static_cast<const btCollisionObject*>(p0->m_clientObject);
        const btCollisionObject* b = static_cast<const btCollisionObject*>(p1->m_clientObject);
        return a->getUserIndex() <= 0 || a->getUserIndex() != b->getUserIndex();
    }
};

// an orthonormal basis whose X column is the unit vector x
static btMatrix3x3 basis_x(const btVector3& x) {
    btVector3 y, z;
    btPlaneSpace1(x, y, z);
    return btMatrix3x3(x.x(), y.x(), z.x(), x.y(), y.y(), z.y(), x.z(), y.z(), z.z());
}

static btVector3 bt(ak_vec3 v) { return btVector3(v.x, v.y, v.z); }

// Bullet at its defaults (iterations 10, substeps 1) or, for --sweep, with `iterations` solver
// iterations and each step of 1/60 s taken as `substeps` calls of stepSimulation(h, 1, h),
// h = dt / substeps (the same as Bullet's own fixed substeps, without its accumulator's
// rounding: each call is exactly one internal step)
static result run_bullet(const scene& sc, int steps, int iterations = 10, int substeps = 1,
                         bool track = false) {
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    group_filter filter;
    broadphase.getOverlappingPairCache()->setOverlapFilterCallback(&filter);
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    world.getSolverInfo().m_numIterations = iterations;
    world.setGravity(btVector3(0, -9.81f, 0));
    std::vector<btCollisionShape*> shapes;
    std::vector<btRigidBody*> bodies;
    std::vector<btDefaultMotionState*> states;
    for (const ak_rigid_body_desc& d : sc.bodies) {
        btCollisionShape* shape;
        btScalar mass = 0;
        if (d.shape.type == AK_RIGID_PLANE) {
            btVector3 nrm(d.shape.normal.x, d.shape.normal.y, d.shape.normal.z);
            shape = new btStaticPlaneShape(nrm, nrm.dot(btVector3(d.position.x, d.position.y, d.position.z)));
        } else if (d.shape.type == AK_RIGID_BOX) {
            btVector3 he(d.shape.half_extents.x, d.shape.half_extents.y, d.shape.half_extents.z);
            shape = new btBoxShape(he);
            mass = 1000.0f * 8.0f * he.x() * he.y() * he.z();
        } else if (d.shape.type == AK_RIGID_CAPSULE) {
            // the same mass as animkit's (density 1000 or the desc's); Bullet's own inertia
            const float rr = d.shape.radius, hh = d.shape.half_height;
            shape = new btCapsuleShape(rr, 2.0f * hh);
            mass = (d.density > 0 ? d.density : 1000.0f) * 3.14159265f * rr * rr * (2.0f * hh + 4.0f / 3.0f * rr);
        } else {
            shape = new btSphereShape(d.shape.radius);
            mass = 1000.0f * 4.0f / 3.0f * 3.14159265f * d.shape.radius * d.shape.radius * d.shape.radius;
        }
        btVector3 inertia(0, 0, 0);
        if (mass > 0) shape->calculateLocalInertia(mass, inertia);
        btTransform t;
        t.setIdentity();
        if (d.shape.type != AK_RIGID_PLANE) {
            t.setOrigin(btVector3(d.position.x, d.position.y, d.position.z));
            const ak_quat o = d.orientation;
            if (o.x != 0 || o.y != 0 || o.z != 0 || o.w != 0) t.setRotation(btQuaternion(o.x, o.y, o.z, o.w).normalized());
        }
        btDefaultMotionState* ms = new btDefaultMotionState(t);
        btRigidBody::btRigidBodyConstructionInfo info(mass, ms, shape, inertia);
        info.m_friction = d.friction > 0 ? d.friction : 0.5f;
        btRigidBody* b = new btRigidBody(info);
        b->setUserIndex((int)d.collision_group);
        b->setLinearVelocity(bt(d.velocity));
        b->setAngularVelocity(bt(d.angular_velocity));
        if (g_sleep == SLEEP_OFF) b->setActivationState(DISABLE_DEACTIVATION);
        world.addRigidBody(b);
        shapes.push_back(shape);
        bodies.push_back(b);
        states.push_back(ms);
    }
    // joints: ball with a cone -> btConeTwistConstraint (twist axis X = the joint axis), free
    // ball -> btPoint2PointConstraint, hinge -> btHingeConstraint with the limits shifted by the
    // built pose's angle, fixed -> btFixedConstraint; jointed bodies do not collide
    std::vector<btTypedConstraint*> constraints;
    std::vector<btVector3> pivots;  // per joint: pivot in a, pivot in b (for the gap)
    for (const ak_rigid_joint_desc& j : sc.joints) {
        btRigidBody& a = *bodies[j.body_a];
        btRigidBody& b = *bodies[j.body_b];
        const btTransform ta = a.getCenterOfMassTransform(), tb = b.getCenterOfMassTransform();
        const btVector3 anchor = bt(j.anchor);
        btVector3 axis = bt(j.axis);
        if (axis.length2() == 0) axis = btVector3(0, 0, 1);
        axis.normalize();
        btVector3 axis_b = j.axis_b.x != 0 || j.axis_b.y != 0 || j.axis_b.z != 0 ? bt(j.axis_b).normalized() : axis;
        const btVector3 pa = ta.inverse() * anchor, pb = tb.inverse() * anchor;
        btTypedConstraint* c = nullptr;
        if (j.type == AK_RIGID_JOINT_HINGE) {
            btHingeConstraint* h = new btHingeConstraint(a, b, pa, pb, ta.getBasis().transpose() * axis,
                                                         tb.getBasis().transpose() * axis_b);
            if (j.limited) h->setLimit(j.lower - j.angle_offset, j.upper - j.angle_offset);
            c = h;
        } else if (j.type == AK_RIGID_JOINT_BALL && (j.limited || j.twist_limited)) {
            const btMatrix3x3 wa = basis_x(axis), wb = btMatrix3x3(shortestArcQuat(axis, axis_b)) * wa;
            btTransform fa(ta.getBasis().transpose() * wa, pa), fb(tb.getBasis().transpose() * wb, pb);
            btConeTwistConstraint* ct = new btConeTwistConstraint(a, b, fa, fb);
            const float swing = j.limited ? j.upper : SIMD_PI;
            const float twist = j.twist_limited ? std::fmax(std::fabs(j.twist_lower + j.angle_offset),
                                                            std::fabs(j.twist_upper + j.angle_offset))
                                                : SIMD_PI;
            ct->setLimit(swing, swing, twist);
            c = ct;
        } else if (j.type == AK_RIGID_JOINT_FIXED) {
            btTransform fa(ta.getBasis().transpose(), pa), fb(tb.getBasis().transpose(), pb);
            c = new btFixedConstraint(a, b, fa, fb);
        } else {
            c = new btPoint2PointConstraint(a, b, pa, pb);  // free ball (prismatic: not in these scenes)
        }
        world.addConstraint(c, true);
        constraints.push_back(c);
        pivots.push_back(pa);
        pivots.push_back(pb);
    }
    result r = {};
    const btScalar dt = 1.0f / 60.0f, h = dt / (btScalar)substeps;
    // --sweep: a model of the scene for ak_rigid_joint_error, and the poses copied out of Bullet
    ak_rigid_model* model = nullptr;
    std::vector<ak_vec3> px(sc.bodies.size());
    std::vector<ak_quat> pq(sc.bodies.size());
    if (track) {
        ak_rigid_model_desc md;
        std::memset(&md, 0, sizeof md);
        md.bodies.ptr = sc.bodies.data();
        md.bodies.count = sc.bodies.size();
        md.joints.ptr = sc.joints.data();
        md.joints.count = sc.joints.size();
        if (ak_rigid_model_create(&md, nullptr, &model) != AK_OK) return r;
    }
    const double t0 = bench_cpu_s();
    double in_probe = 0.0;
    for (int s = 0; s < steps; ++s) {
        for (int k = 0; k < substeps; ++k)
            world.stepSimulation(substeps > 1 ? h : dt, 1, substeps > 1 ? h : dt);
        const double p0 = bench_cpu_s();
        if (track) {
            for (size_t i = 0; i < bodies.size(); ++i) {
                const btTransform t = bodies[i]->getCenterOfMassTransform();
                const btQuaternion o = t.getRotation();
                px[i] = ak_vec3_make(t.getOrigin().x(), t.getOrigin().y(), t.getOrigin().z());
                pq[i] = ak_quat{o.x(), o.y(), o.z(), o.w()};
                if (i < sc.planes)
                    px[i] = sc.bodies[i].position; // Bullet's plane sits at the origin
            }
            probe(sc, model, px, pq, &r);
        }
        for (int k = 0; k < dispatcher.getNumManifolds(); ++k) {
            btPersistentManifold* mf = dispatcher.getManifoldByIndexInternal(k);
            r.contacts += mf->getNumContacts() / (double)steps;
            for (int c = 0; c < mf->getNumContacts(); ++c)
                r.pen = std::fmax(r.pen, -(double)mf->getContactPoint(c).getDistance());
        }
        in_probe += bench_cpu_s() - p0;
    }
    r.ms_per_step = 1e3 * (bench_cpu_s() - t0 - in_probe) / steps;
    for (size_t k = 0; k < sc.joints.size(); ++k) {
        const btVector3 wa = bodies[sc.joints[k].body_a]->getCenterOfMassTransform() * pivots[2 * k];
        const btVector3 wb = bodies[sc.joints[k].body_b]->getCenterOfMassTransform() * pivots[2 * k + 1];
        r.drift = std::fmax(r.drift, (double)(wa - wb).length());
    }
    for (size_t k = 0; k < constraints.size(); ++k) {
        world.removeConstraint(constraints[k]);
        delete constraints[k];
    }
    for (size_t i = sc.planes; i < bodies.size() && sc.joints.empty(); ++i) {
        btVector3 p = bodies[i]->getCenterOfMassPosition();
        r.drift = std::fmax(r.drift, std::hypot((double)(p.x() - sc.bodies[i].position.x),
                                                (double)(p.z() - sc.bodies[i].position.z)));
    }
    ak_rigid_model_destroy(model);
    for (size_t i = 0; i < bodies.size(); ++i) {
        world.removeRigidBody(bodies[i]);
        delete bodies[i];
        delete states[i];
        delete shapes[i];
    }
    return r;
}

// "2,3,4" -> {2, 3, 4}; empty on a bad entry
static std::vector<int> int_list(const char* s) {
    std::vector<int> v;
    for (const char* p = s; *p;) {
        char* end = nullptr;
        const long k = std::strtol(p, &end, 10);
        if (end == p || k < 1 || k > 1000) return {};
        v.push_back((int)k);
        p = *end == ',' ? end + 1 : end;
        if (*end && *end != ',') return {};
    }
    return v;
}

struct sweep_row {
    bool bullet;
    int a, b;               // animkit: substeps, contacts_after_joints; Bullet: iterations, substeps
    result r;               // the first round's (both engines are deterministic: the measures
                            // are the same every round)
    std::vector<double> ms; // ms per step, one per round
    int it = 1;             // animkit: contact_iterations
    double med = 0, lo = 0, hi = 0;
};

static sweep_row make_row(bool bullet, int a, int b) {
    sweep_row row;
    row.bullet = bullet;
    row.a = a;
    row.b = b;
    row.r = result();
    return row;
}

// whether x is as stable as y or more on every measure of the scene: pyramid and spheres the
// largest drift (pyramid only: the spheres are meant to spread), penetration and bodies behind a
// plane; ragdolls the widest joint gap, the largest limit excess, penetration and bodies behind
// a plane
static bool as_stable(const scene& sc, bool spheres, const result& x, const result& y) {
    if (x.pen > y.pen || x.escaped > y.escaped) return false;
    if (!sc.joints.empty()) return x.gap_max <= y.gap_max && x.limit_max <= y.limit_max;
    return spheres || x.drift_max <= y.drift_max;
}

// --sweep: per scene, animkit at each of ak_subs and Bullet at each of bt_iters x bt_subs,
// `rounds` rounds interleaved (every setting once per round), the probes after every step; then
// the cheapest animkit setting as stable as Bullet's defaults on every measure, and the cheapest
// Bullet setting as stable as animkit at ak_ref substeps
static void sweep(const char* name, const scene& sc, int steps, unsigned threads, int rounds,
                  int ak_ref, const std::vector<int>& ak_subs, const std::vector<int>& ak_its,
                  const std::vector<int>& bt_iters, const std::vector<int>& bt_subs) {
    std::vector<sweep_row> rows;
    for (int k : ak_subs)
        for (int it : ak_its)
            for (int aj = 0; aj < (g_after_joints ? 2 : 1); ++aj) {
                rows.push_back(make_row(false, k, aj));
                rows.back().it = it;
            }
    if (std::find(ak_subs.begin(), ak_subs.end(), ak_ref) == ak_subs.end())
        rows.push_back(make_row(false, ak_ref, 0));
    rows.push_back(make_row(true, 10, 1)); // Bullet's defaults, always
    for (int it : bt_iters)
        for (int sub : bt_subs)
            if (it != 10 || sub != 1) rows.push_back(make_row(true, it, sub));
    for (int round = 0; round < rounds; ++round)
        for (sweep_row& row : rows) {
            const result r = row.bullet ? run_bullet(sc, steps, row.a, row.b, true)
                                        : run_animkit(sc, steps, (unsigned)row.a, threads, true,
                                                      row.b != 0, (unsigned)row.it);
            if (!round) row.r = r;
            row.ms.push_back(r.ms_per_step);
        }
    const bool is_spheres = !std::strcmp(name, "spheres");
    std::printf("\nsweep: %s (%zu bodies), %d steps, %d round(s); ms per step: median (range) of "
                "the rounds; "
                "measures: max over all steps\n",
                name, sc.bodies.size() - sc.planes, steps, rounds);
    std::printf("%-8s %-22s %22s %11s %11s %10s %11s %7s %8s\n", "engine", "setting", "ms per step",
                "drift mm", "pen mm", "gap mm", "limit deg", "behind", "pts");
    for (sweep_row& row : rows) {
        std::vector<double> v = row.ms;
        std::sort(v.begin(), v.end());
        row.med = v[v.size() / 2];
        row.lo = v.front();
        row.hi = v.back();
        char setting[64], ms[64];
        if (row.bullet)
            std::snprintf(setting, sizeof setting, "%d iterations x %d sub", row.a, row.b);
        else if (row.it > 1)
            std::snprintf(setting, sizeof setting, row.b ? "%d sub x %d it, after j." : "%d sub x %d it",
                          row.a, row.it);
        else
            std::snprintf(setting, sizeof setting, row.b ? "%d sub, after joints" : "%d substeps",
                          row.a);
        std::snprintf(ms, sizeof ms, "%.3f (%.3f-%.3f)", row.med, row.lo, row.hi);
        std::printf("%-8s %-22s %22s %11.3f %11.3f %10.3f %11.3f %7d %8.0f\n",
                    row.bullet ? "Bullet" : "animkit", setting, ms, 1e3 * row.r.drift_max,
                    1e3 * row.r.pen, 1e3 * row.r.gap_max,
                    row.r.limit_max * 180.0 / 3.14159265358979, row.r.escaped, row.r.contacts);
    }
    const sweep_row* bt_def = nullptr;
    const sweep_row* ak_def = nullptr;
    for (const sweep_row& row : rows) {
        if (row.bullet && row.a == 10 && row.b == 1) bt_def = &row;
        if (!row.bullet && row.a == ak_ref && !row.b && row.it == 1) ak_def = &row;
    }
    const sweep_row* ak_best = nullptr;
    const sweep_row* bt_best = nullptr;
    for (const sweep_row& row : rows) {
        if (!row.bullet && as_stable(sc, is_spheres, row.r, bt_def->r) &&
            (!ak_best || row.med < ak_best->med))
            ak_best = &row;
        if (row.bullet && as_stable(sc, is_spheres, row.r, ak_def->r) &&
            (!bt_best || row.med < bt_best->med))
            bt_best = &row;
    }
    if (ak_best)
        std::printf("matched to Bullet's defaults (10 iterations x 1 sub, %.3f ms): animkit at %d "
                    "substeps x %d contact iterations%s, %.3f ms: "
                    "ratio (Bullet / animkit) %.2f (%.2f-%.2f)\n",
                    bt_def->med, ak_best->a, ak_best->it, ak_best->b ? " (contacts after joints)" : "",
                    ak_best->med, bt_def->med / ak_best->med,
                    bt_def->lo / ak_best->hi, bt_def->hi / ak_best->lo);
    else
        std::printf("matched to Bullet's defaults: no animkit setting tried is as stable on every "
                    "measure\n");
    if (bt_best)
        std::printf("matched to animkit at %d substeps (%.3f ms): Bullet at %d iterations x %d "
                    "sub, %.3f ms: ratio "
                    "(Bullet / animkit) %.2f (%.2f-%.2f)\n",
                    ak_ref, ak_def->med, bt_best->a, bt_best->b, bt_best->med,
                    bt_best->med / ak_def->med, bt_best->lo / ak_def->hi, bt_best->hi / ak_def->lo);
    else
        std::printf("matched to animkit at %d substeps: no Bullet setting tried is as stable on "
                    "every measure\n",
                    ak_ref);
    std::fflush(stdout);
}

int main(int argc, char** argv) {
    int layers = 20, nspheres = 10000, nragdolls = 50, steps = 300;
    unsigned substeps = 20, threads = 1;
    const char* only = nullptr;
    bool do_sweep = false;
    int rounds = 3, ak_ref = 10;
    std::vector<int> ak_subs = {2, 3, 4, 6, 10}, ak_its = {1}, bt_iters = {10, 20, 50},
                     bt_subs = {1, 2, 4};
    bool lists_ok = true;
    for (int i = 1; i < argc; i += 2) {
        if (!std::strcmp(argv[i], "--sweep")) { // a flag without a value
            do_sweep = true;
            --i;
            continue;
        }
        if (!std::strcmp(argv[i], "--no-anchors")) { // a flag without a value
            g_anchors = false;
            --i;
            continue;
        }
        if (!std::strcmp(argv[i], "--contacts-after-joints")) { // a flag without a value
            g_after_joints = true;
            --i;
            continue;
        }
        if (i + 1 >= argc) break;
        if (!std::strcmp(argv[i], "--sleep")) {
            if (!std::strcmp(argv[i + 1], "own"))
                g_sleep = SLEEP_OWN;
            else if (!std::strcmp(argv[i + 1], "bullet"))
                g_sleep = SLEEP_BULLET;
            else if (!std::strcmp(argv[i + 1], "off"))
                g_sleep = SLEEP_OFF;
            else
                lists_ok = false;
        } else if (!std::strcmp(argv[i], "--rounds"))
            rounds = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--ak-ref"))
            ak_ref = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--ak-iterations"))
            lists_ok &= !(ak_its = int_list(argv[i + 1])).empty();
        else if (!std::strcmp(argv[i], "--contact-iterations"))
            g_iterations = (unsigned)std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--ak-substeps"))
            lists_ok &= !(ak_subs = int_list(argv[i + 1])).empty();
        else if (!std::strcmp(argv[i], "--bt-iterations"))
            lists_ok &= !(bt_iters = int_list(argv[i + 1])).empty();
        else if (!std::strcmp(argv[i], "--bt-substeps"))
            lists_ok &= !(bt_subs = int_list(argv[i + 1])).empty();
        else if (!std::strcmp(argv[i], "--layers"))
            layers = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--spheres")) nspheres = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--steps")) steps = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--substeps")) substeps = (unsigned)std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--ragdolls")) nragdolls = std::atoi(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--only")) only = argv[i + 1];
        else if (!std::strcmp(argv[i], "--threads")) threads = (unsigned)std::atoi(argv[i + 1]);
    }
    if (layers < 1 || layers > 200 || nspheres < 1 || nspheres > 1000000 || nragdolls < 1 ||
        nragdolls > 10000 || steps < 1 || substeps < 1 || substeps > 1000 || threads < 1 ||
        threads > 64 || g_iterations < 1 || g_iterations > 64 || !lists_ok || rounds < 1 || rounds > 100 || ak_ref < 1 || ak_ref > 1000) {
        std::fprintf(
            stderr,
            "usage: bench_rigid_vs_bullet [--layers L] [--spheres N] [--ragdolls R] [--steps S] "
            "[--substeps K] [--threads T] [--only pyramid|spheres|ragdolls] [--no-anchors]\n"
            "       [--sleep own|bullet|off] [--contacts-after-joints] [--contact-iterations K]\n"
            "       [--sweep [--rounds R] [--ak-substeps 2,3,4,6,10] [--ak-iterations 1] [--ak-ref 10] "
            "[--bt-iterations 10,20,50] [--bt-substeps 1,2,4]]\n");
        return 2;
    }
    std::printf("dt 1/60 s, %d steps, %s; animkit XPBD %u substeps x 1 iteration, %u thread(s)%s%s; Bullet "
                "%d.%02d 1 step x 10 iterations (its defaults), one thread\n",
                steps, sleep_name(), substeps, threads, threads > 1 ? " (wall time)" : "",
                g_anchors ? (g_after_joints ? ", contact anchors, contacts after joints" : ", contact anchors")
                          : ", no contact anchors", btGetVersion() / 100,
                btGetVersion() % 100);
    if (!do_sweep)
        std::printf("%-26s %11s %11s %7s %13s %13s %12s %12s %9s %9s\n", "scene", "animkit ms",
                    "Bullet ms", "ratio", "animkit drift", "Bullet drift", "animkit pen",
                    "Bullet pen", "ak pts", "bt pts");
    const char* names[3] = {"pyramid", "spheres", "ragdolls"};
    scene scenes[3];
    if (!only || !std::strcmp(only, names[0])) scenes[0] = pyramid(layers);
    if (!only || !std::strcmp(only, names[1])) scenes[1] = spheres(nspheres);
    if ((!only || !std::strcmp(only, names[2])) && !ragdolls(nragdolls, &scenes[2])) {
        std::fprintf(stderr, "bench_rigid_vs_bullet: the ragdolls cannot be built\n");
        return 1;
    }
    if (do_sweep) {
        for (int k = 0; k < 3; ++k)
            if (!scenes[k].bodies.empty())
                sweep(names[k], scenes[k], steps, threads, rounds, ak_ref, ak_subs, ak_its,
                      bt_iters, bt_subs);
        std::printf("\nmatched: the cheapest setting (median time) whose every measure is at most "
                    "the other\n"
                    "engine's reference; drift: largest horizontal displacement of a body from its "
                    "start (not\n"
                    "a measure for the spheres, which spread); gap: widest joint anchor gap; "
                    "limit: largest joint\n"
                    "angle outside its limits; behind: most bodies more than 5 cm behind a plane "
                    "at one step;\n"
                    "pen: deepest penetration after a step; all over every step of the run "
                    "(ak_rigid_joint_error\n"
                    "measures both engines' poses); pts: contact points per step (first round)\n");
        return 0;
    }
    for (int k = 0; k < 3; ++k) {
        if (scenes[k].bodies.empty()) continue;
        result a = run_animkit(scenes[k], steps, substeps, threads);
        result b = run_bullet(scenes[k], steps);
        char label[64];
        std::snprintf(label, sizeof label, "%s (%zu bodies)", names[k], scenes[k].bodies.size() - scenes[k].planes);
        std::printf("%-26s %11.3f %11.3f %7.3f %13.3g %13.3g %12.3g %12.3g %9.0f %9.0f\n", label, a.ms_per_step,
                    b.ms_per_step, b.ms_per_step / a.ms_per_step, a.drift, b.drift, a.pen, b.pen, a.contacts,
                    b.contacts);
        std::printf("  animkit final state FNV-1a %016llx\n", (unsigned long long)a.hash);
        if (a.dropped)
            std::printf("  WARNING: animkit DROPPED %llu contact points over max_contacts in %d of %d steps "
                        "(from step %d): its simulation of this scene is broken and its timing not comparable\n",
                        (unsigned long long)a.dropped, a.drop_steps, steps, a.drop_first);
        else
            std::printf("  animkit dropped no contacts (max_contacts held every pair)\n");
        // where animkit's time went: the calling thread's CPU, every thread's (the worker team's
        // included, so the islands' share off the calling thread shows), and wall time
        std::printf("  animkit ms per step: calling thread CPU %.3f, all threads CPU %.3f (%.0f%% off the "
                    "calling thread), wall %.3f\n",
                    a.cpu_ms, a.proc_ms, a.proc_ms > 0 ? 100.0 * (a.proc_ms - a.cpu_ms) / a.proc_ms : 0.0,
                    a.wall_ms);
        std::fflush(stdout);
    }
    std::printf("ratio = Bullet time / animkit time (above 1: animkit faster); drift: largest horizontal\n"
                "displacement of a body from its start (pyramid: should be ~0; ragdolls: the widest joint gap at\n"
                "the end); pen: deepest penetration seen; pts: contact points per step; thread CPU time (animkit\n"
                "with --threads above 1: wall time)\n");
    return 0;
}
