/* XPBD rigid-body step (Mueller et al. 2020) with an implicit gyroscopic term, sweep-and-prune
 * broad phase and sleeping groups. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rigid_impl.h"
#include "../tasks.h"

/* Small helpers of the solver's inner loops, inlined into every caller (the islands call the
 * substep's phases from a second place, and the compiler then stops inlining some of them). */
#if defined(__GNUC__) || defined(__clang__)
#define RIGID_HOT static inline __attribute__((always_inline))
#else
#define RIGID_HOT static inline
#endif

typedef struct sap_entry {
    float lo, hi;
    uint32_t body;
} sap_entry;

/* The contacts of one pair of bodies, c[start, end), and its place in the solve order. */
typedef struct contact_group {
    uint32_t start, end;
    float height; /* the pair's midpoint against gravity: higher pairs are solved first */
    /* the centre of pressure after the position solve (the velocity solve reads it again) */
    uint32_t pressed;
    uint32_t patch; /* at least two contacts pushed, both bodies moving, neither round: a face
                       or an edge line on a face (see patch_slip) */
    uint32_t stuck; /* a patch whose static friction held this substep */
    ak_vec3 la, lb;
    float lambda, arm;
    ak_vec3 ra, rb; /* its world offsets after the position solve (zero for a body that does
                       not move), which the velocity solve's friction reuses */
    float wr;       /* n . I^-1 n summed over the two bodies */
    ak_vec3 carry;  /* the pair's anchor drift left from earlier steps (world; see
                       ak_rigid_contact_anchor), added to the slip static friction undoes */
    float carry_twist; /* and its twist about n (a against b, radians) */
} contact_group;

/* A pair of bodies the broad phase found at the step's start. Pairs of boxes and planes
 * (flat faces and corners: their contact points are fixed on the bodies) keep the contacts
 * found then, c[start, end), for every substep; other pairs (spheres, capsules: the contact
 * point rolls over the surface) run the narrow phase again in each substep. */
typedef struct pair_entry {
    uint32_t a, b; /* the awake (or lower-index) body first: a static body is always b */
    uint32_t start, end;
    float height; /* the pair's midpoint against gravity: higher pairs are solved first */
    uint32_t cached;
    ak_vec3 carry; /* cached pairs: the anchor drift from the job's contact anchors (world, along
                      the contact plane at the step's start); zero without one */
    float carry_twist; /* and the anchor's twist about the normal (radians, a against b) */
} pair_entry;

/* One contact's row, set once per substep on the poses after the joints' first sweep: the
 * world arms' responses to a unit impulse along the normal. Within the position solve a body's
 * corrections are summed as a displacement cx and a rotation vector ct, and the contact's
 * depth is read to first order, d = d0 + n . (cx_b - cx_a) + ct_b . rnb - ct_a . rna (the
 * exact pose moves a point by cx + ct x r: second-order terms, (ct)^2 r, are under 1e-6 of
 * the correction); the velocity solve reuses the same arms. */
typedef struct contact_row {
    ak_vec3 rna, rnb; /* ra x n, rb x n (zero for a body that does not move) */
    ak_vec3 ta, tb;   /* I^-1 (r x n) (zero for a body that does not move) */
    float ima, imb;   /* inverse masses (zero for a body that does not move) */
    float d0;         /* depth at the row's set-up */
    float inv_w;      /* 1 / (generalised inverse masses), 0 when neither body moves */
} contact_row;

/* An island: dynamic bodies joined by the step's pairs and by joints (union-find; static
 * bodies join nothing, since no island writes them). Its bodies, pairs, joints and joint chains
 * are runs of the step's island-ordered lists (each run in the global order), and its
 * non-cached pairs' contacts go to a region of the contact buffer of its own, so islands are
 * solved one after another or at the same time with the same numbers as the one-island solve. */
typedef struct island {
    uint32_t body0, body1, pair0, pair1, joint0, joint1, chain0, chain1;
    uint32_t region, region_end; /* contact buffer [region, region_end) */
    uint32_t count_last;         /* contacts of the last substep in the region */
    uint32_t dropped;
    uint32_t work; /* a cost estimate, to share islands out over the threads */
    bool awake;    /* some body of it moves (else nothing to solve) */
} island;

/* Scratch layout, in 16-byte aligned blocks. */
typedef struct layout {
    size_t x0, q0, v0, w0, qp, dx, ds, iw, grow, slack, launch, sap, pairs, contacts, groups, rows,
        cx, ct, jorder, jstart, jchain, croot, rot, rot0, parent, awake, island_of, ibodies,
        ipairs, ijoints, ichains, islands, held, total;
} layout;

static size_t align16(size_t s) { return (s + 15) & ~(size_t)15; }

static layout layout_of(const ak_rigid_model* m) {
    layout l;
    size_t n = m->body_count, off = 0;
    l.x0 = off, off += align16(n * sizeof(ak_vec3));
    l.q0 = off, off += align16(n * sizeof(ak_quat));
    l.v0 = off, off += align16(n * sizeof(ak_vec3));
    l.w0 = off, off += align16(n * sizeof(ak_vec3));
    l.qp = off, off += align16(n * sizeof(ak_quat));
    l.dx = off, off += align16(n * sizeof(ak_vec3));
    l.ds = off, off += align16(n * sizeof(ak_vec3));
    l.iw = off, off += align16(n * sizeof(ak_mat3));
    l.grow = off, off += align16(n * sizeof(float));
    l.slack = off, off += align16(n * sizeof(float));
    l.launch = off, off += align16(n * sizeof(float));
    l.sap = off, off += align16(n * sizeof(sap_entry));
    l.pairs = off, off += align16((size_t)m->desc.max_contacts * sizeof(pair_entry));
    l.contacts = off, off += align16(((size_t)m->desc.max_contacts + AKP_RIGID_MAX_PAIR_CONTACTS) *
                                     sizeof(rigid_contact));
    l.groups = off, off += align16(((size_t)m->desc.max_contacts + AKP_RIGID_MAX_PAIR_CONTACTS) *
                                   sizeof(contact_group));
    l.rows = off, off += align16(((size_t)m->desc.max_contacts + AKP_RIGID_MAX_PAIR_CONTACTS) *
                                 sizeof(contact_row));
    l.cx = off, off += align16(n * sizeof(ak_vec3));
    l.ct = off, off += align16(n * sizeof(ak_vec3));
    l.jorder = off, off += align16(m->joint_count * sizeof(uint32_t));
    l.jstart = off, off += align16((m->joint_count + 1) * sizeof(uint32_t));
    l.jchain = off, off += align16(m->joint_count * sizeof(uint32_t));
    l.croot = off, off += align16(n * sizeof(uint32_t));
    l.rot = off, off += align16(n * sizeof(ak_mat3));
    l.rot0 = off, off += align16(n * sizeof(ak_mat3));
    l.parent = off, off += align16(n * sizeof(uint32_t));
    l.awake = off, off += align16(n);
    l.island_of = off, off += align16(n * sizeof(uint32_t));
    l.ibodies = off, off += align16(n * sizeof(uint32_t));
    l.ipairs = off, off += align16((size_t)m->desc.max_contacts * sizeof(pair_entry));
    l.ijoints = off, off += align16(m->joint_count * sizeof(uint32_t));
    l.ichains = off, off += align16(m->joint_count * sizeof(uint32_t));
    l.islands = off, off += align16(n * sizeof(struct island));
    l.held = off, off += align16((size_t)m->desc.max_contacts + AKP_RIGID_MAX_PAIR_CONTACTS);
    l.total = off + 16; /* room to align the base */
    return l;
}

size_t ak_rigid_step_scratch_size(const ak_rigid_step_job* job) {
    if (!job || !job->model) return 0;
    return layout_of(job->model).total;
}

/* The contact anchor cache's order: (body_a, body_b) ascending. */
static bool anchor_before(const ak_rigid_contact_anchor* x, const ak_rigid_contact_anchor* y) {
    return x->body_a < y->body_a || (x->body_a == y->body_a && x->body_b < y->body_b);
}

ak_result ak_rigid_step_validate(const ak_rigid_step_job* job) {
    if (!job || !job->model) return AK_ERR_NULL_ARG;
    if (!(job->dt > 0.0f) || !ak_finitef(job->dt) || job->substeps > 1000 ||
        job->thread_count > AK_RIGID_MAX_THREADS || !ak_vec3_is_finite(job->gravity))
        return AK_ERR_BAD_ARG;
    size_t n = job->model->body_count;
    if (!job->positions.ptr || !job->orientations.ptr || !job->velocities.ptr ||
        !job->angular_velocities.ptr || !job->scratch.ptr)
        return AK_ERR_NULL_ARG;
    if (job->positions.count < n || job->orientations.count < n || job->velocities.count < n ||
        job->angular_velocities.count < n ||
        (job->sleep_timers.count != 0 && job->sleep_timers.count < n) ||
        (job->sleep_timers.count != 0 && !job->sleep_timers.ptr) ||
        job->scratch.count < ak_rigid_step_scratch_size(job))
        return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i) {
        if (!ak_vec3_is_finite(job->positions.ptr[i]) ||
            !ak_quat_is_finite(job->orientations.ptr[i]) ||
            !ak_vec3_is_finite(job->velocities.ptr[i]) ||
            !ak_vec3_is_finite(job->angular_velocities.ptr[i]))
            return AK_ERR_BAD_DATA;
        if (job->sleep_timers.count && !ak_finitef(job->sleep_timers.ptr[i]))
            return AK_ERR_BAD_DATA;
    }
    if (job->contact_anchors.count) {
        if (!job->contact_anchors.ptr || !job->contact_anchor_count) return AK_ERR_NULL_ARG;
        uint32_t na = *job->contact_anchor_count;
        if (na > job->contact_anchors.count) return AK_ERR_BAD_DATA;
        for (uint32_t k = 0; k < na; ++k) {
            const ak_rigid_contact_anchor* e = &job->contact_anchors.ptr[k];
            if (!(e->body_a < e->body_b) || e->body_b >= n || !ak_vec3_is_finite(e->drift) ||
                !ak_vec3_is_finite(e->normal) || !ak_finitef(e->twist))
                return AK_ERR_BAD_DATA;
            if (k && !anchor_before(&job->contact_anchors.ptr[k - 1], e)) return AK_ERR_BAD_DATA;
        }
    }
    if (job->drive_targets.count) {
        if (!job->drive_targets.ptr) return AK_ERR_NULL_ARG;
        if (job->drive_targets.count < job->model->joint_count) return AK_ERR_SPAN_SMALL;
        for (size_t k = 0; k < job->model->joint_count; ++k)
            if (!ak_quat_is_finite(job->drive_targets.ptr[k]) ||
                !(ak_quat_dot(job->drive_targets.ptr[k], job->drive_targets.ptr[k]) > 0.0f))
                return AK_ERR_BAD_DATA;
    }
    return AK_OK;
}

typedef struct solver {
    const ak_rigid_model* m;
    const rigid_body* bodies;
    ak_vec3* x;
    ak_quat* q;
    ak_vec3* v;
    ak_vec3* w;
    const ak_vec3* x0; /* positions at the step's start */
    ak_quat* qp;
    ak_vec3* dx;          /* displacement since the substep's start, kept apart so the velocity
                             dx / h keeps float precision far from the origin */
    ak_vec3* ds;          /* displacement from the step's start to this substep's start; x is
                             always x0 + (ds + dx), rounded once, so a body 100 m out does not
                             lose a rounding of its position every substep (4 mm/s at 1200 Hz) */
    const ak_quat* q0;    /* orientations at the step's start */
    const uint8_t* awake; /* 1: dynamic and awake (moves); 0: static or asleep */
    ak_mat3* iw;          /* world inverse inertia R diag(I^-1) R^T at the substep's start */
    const ak_quat* drive_targets; /* the job's, per joint; NULL -> the model's */
    contact_row* rows;            /* per contact of the substep */
    ak_vec3* cx;    /* the contact solve's displacement of each body (see contact_row) */
    ak_vec3* ct;    /* the contact solve's rotation vector of each body */
    ak_mat3* rot;   /* each body's rotation at the contact solve's start */
    ak_mat3* rot0;  /* each body's rotation at the step's start */
    uint8_t* held; /* per contact: at a cached pair's first contact, whether its static
                      friction held (or had nothing to undo) in the latest substep */
    float h;
    /* after an overflow of max_contacts, the most a contact between two moving bodies
     * corrects in a substep (INFINITY otherwise; see find_pairs) */
    float push_max;
} solver;

/* World inverse inertia R diag(I^-1) R^T of orientation q (symmetric, so its storage order
 * does not matter). The solver takes it once per substep, after the prediction: within a
 * substep a body turns by |w| h (under a thousandth of a radian for 5 rad/s at 1200 Hz), and
 * the tensor only scales the corrections, which are then exact to that order. */
RIGID_HOT ak_mat3 world_inv_inertia(ak_quat q, ak_vec3 ii) {
    ak_mat3 r = ak_mat3_from_quat(q), o;
    for (int row = 0; row < 3; ++row)
        for (int col = row; col < 3; ++col) {
            float v = r.m[row] * ii.x * r.m[col] + r.m[3 + row] * ii.y * r.m[3 + col] +
                      r.m[6 + row] * ii.z * r.m[6 + col];
            o.m[3 * col + row] = v;
            o.m[3 * row + col] = v;
        }
    return o;
}

/* I^-1 (world) applied to v for body i (zero when it does not move). */
RIGID_HOT ak_vec3 inv_inertia_mul(const solver* s, uint32_t i, ak_vec3 v) {
    if (!s->awake[i]) return ak_vec3_zero();
    return ak_mat3_mul_vec3(s->iw[i], v);
}

/* q + [dw, 0] q brought back to unit length by one Newton step for 1 / |.| (a joint's
 * correction turns by well under a radian, so the norm is 1 + |dw|^2 / 2 and the step leaves
 * an error of order |dw|^4: no square root or division on the joints' dependency chain; the
 * orientations are normalised exactly once per substep in update_velocities). */
RIGID_HOT ak_quat turn_by(ak_quat q, ak_vec3 dw) {
    ak_quat r = ak_quat_add(q, ak_quat_mul(ak_quat_make(dw.x, dw.y, dw.z, 0.0f), q));
    return ak_quat_scale(r, 1.5f - 0.5f * ak_quat_dot(r, r));
}

/* Apply positional impulse p at offset r to body i (sign +1 or -1). */
RIGID_HOT void apply_position_impulse(solver* s, uint32_t i, ak_vec3 r, ak_vec3 p, float sign) {
    if (!s->awake[i]) return;
    s->dx[i] = ak_vec3_madd(s->dx[i], p, sign * s->bodies[i].inv_mass);
    s->x[i] = ak_vec3_add(s->x0[i], ak_vec3_add(s->ds[i], s->dx[i]));
    ak_vec3 dw = ak_vec3_scale(ak_mat3_mul_vec3(s->iw[i], ak_vec3_cross(r, p)), sign * 0.5f);
    s->q[i] = turn_by(s->q[i], dw);
}

/* Body i's response to a unit impulse along unit n at offset r: the turn I^-1 (r x n) and the
 * generalised inverse mass 1/m + (r x n) . I^-1 (r x n); the contact loops compute it once and
 * use it for both the multiplier and the update. */
typedef struct response {
    ak_vec3 turn;
    float w;
} response;

RIGID_HOT response respond(const solver* s, uint32_t i, ak_vec3 r, ak_vec3 n) {
    response o = {ak_vec3_zero(), 0.0f};
    if (!s->awake[i]) return o;
    ak_vec3 rn = ak_vec3_cross(r, n);
    o.turn = ak_mat3_mul_vec3(s->iw[i], rn);
    o.w = s->bodies[i].inv_mass + ak_vec3_dot(rn, o.turn);
    return o;
}

/* Velocity impulse mag * n on body i. */
RIGID_HOT void push_along(solver* s, uint32_t i, ak_vec3 n, float mag, response o) {
    if (!s->awake[i]) return;
    s->v[i] = ak_vec3_madd(s->v[i], n, mag * s->bodies[i].inv_mass);
    s->w[i] = ak_vec3_madd(s->w[i], o.turn, mag);
}

/* Angular velocity after one implicit (backward Euler) step of Euler's equations without torque,
 * I w' = -w x (I w), linearised once about w (Newton's first iterate), in the body frame. */
RIGID_HOT ak_vec3 gyroscopic_step(ak_vec3 w, ak_vec3 inertia, float h) {
    ak_vec3 iw = ak_vec3_mul(inertia, w);
    ak_vec3 f = ak_vec3_scale(ak_vec3_cross(w, iw), h);
    /* J = I + h (skew(w) I - skew(I w)) */
    ak_mat3 sw = {{0, w.z, -w.y, -w.z, 0, w.x, w.y, -w.x, 0}};
    ak_mat3 siw = {{0, iw.z, -iw.y, -iw.z, 0, iw.x, iw.y, -iw.x, 0}};
    ak_mat3 j = ak_mat3_add(
        ak_mat3_diagonal(inertia),
        ak_mat3_scale(
            ak_mat3_add(ak_mat3_mul(sw, ak_mat3_diagonal(inertia)), ak_mat3_scale(siw, -1.0f)), h));
    if (fabsf(ak_mat3_determinant(j)) < 1e-30f) return w;
    return ak_vec3_sub(w, ak_mat3_mul_vec3(ak_mat3_inverse(j), f));
}

/* The bodies list[0 .. count) (NULL list: every body). */
static void predict(solver* s, ak_vec3 g, float lin_damp, float ang_damp, const uint32_t* list,
                    uint32_t count) {
    float h = s->h;
    for (uint32_t t = 0; t < count; ++t) {
        uint32_t i = list ? list[t] : t;
        s->qp[i] = s->q[i];
        s->dx[i] = ak_vec3_zero();
        if (!s->awake[i]) continue;
        const rigid_body* b = &s->bodies[i];
        ak_vec3 v = ak_vec3_madd(s->v[i], g, h);
        if (lin_damp > 0.0f) v = ak_vec3_scale(v, 1.0f / (1.0f + h * lin_damp));
        s->v[i] = v;
        s->dx[i] = ak_vec3_scale(v, h);
        s->x[i] = ak_vec3_add(s->x0[i], ak_vec3_add(s->ds[i], s->dx[i]));
        ak_quat q = s->q[i];
        ak_vec3 wl = ak_quat_rotate(ak_quat_conjugate(q), s->w[i]);
        wl = gyroscopic_step(wl, b->inertia, h);
        if (ang_damp > 0.0f) wl = ak_vec3_scale(wl, 1.0f / (1.0f + h * ang_damp));
        ak_vec3 w = ak_quat_rotate(q, wl);
        s->w[i] = w;
        ak_quat dq = ak_quat_mul(ak_quat_make(w.x, w.y, w.z, 0.0f), q);
        s->q[i] = ak_quat_normalize(ak_quat_add(q, ak_quat_scale(dq, 0.5f * h)));
        s->iw[i] = world_inv_inertia(s->q[i], b->inv_inertia);
    }
}

/* Entries ordered by (lo, body): a total order, so every sort gives the same sequence. */
static bool sap_less(const sap_entry* a, const sap_entry* b) {
    return a->lo < b->lo || (a->lo == b->lo && a->body < b->body);
}

/* Shell sort (Ciura's gaps, then insertion): in place, no allocation (qsort may call malloc),
 * and nearly linear on the almost sorted arrays consecutive substeps give. */
static void sap_sort(sap_entry* e, uint32_t n) {
    static const uint32_t gaps[] = {701, 301, 132, 57, 23, 10, 4, 1};
    for (size_t g = 0; g < sizeof gaps / sizeof gaps[0]; ++g) {
        uint32_t gap = gaps[g];
        for (uint32_t i = gap; i < n; ++i) {
            sap_entry t = e[i];
            uint32_t j = i;
            for (; j >= gap && sap_less(&t, &e[j - gap]); j -= gap) e[j] = e[j - gap];
            e[j] = t;
        }
    }
}

typedef struct contact_buf {
    rigid_contact* c;
    uint32_t count, cap;
    uint32_t dropped;
    contact_group* groups;
    uint32_t group_count;
} contact_buf;

RIGID_HOT float contact_vn(const solver* s, const rigid_contact* c);

static void narrow(solver* s, contact_buf* cb, uint32_t a, uint32_t b, float margin) {
    rigid_pose pa = {s->x[a], s->q[a]}, pb = {s->x[b], s->q[b]};
    /* at most the room left (an island's region ends where the next one's starts): the
     * points past it would be dropped below anyway, and the first ones are the same */
    uint32_t room = cb->cap - cb->count;
    int found = akp_rigid_collide(s->m, a, b, pa, pb, margin, cb->c + cb->count,
                                  room < AKP_RIGID_MAX_PAIR_CONTACTS ? (int)room
                                                                    : AKP_RIGID_MAX_PAIR_CONTACTS);
    int kept = found < AKP_RIGID_MAX_PAIR_CONTACTS ? found : AKP_RIGID_MAX_PAIR_CONTACTS;
    if (cb->count + (uint32_t)kept > cb->cap) {
        cb->dropped += (uint32_t)found - room;
        kept = (int)room;
    } else {
        cb->dropped += (uint32_t)(found - kept);
    }
    const rigid_body* ba = &s->bodies[a];
    const rigid_body* bb = &s->bodies[b];
    for (int k = 0; k < kept; ++k) {
        rigid_contact* c = &cb->c[cb->count + (uint32_t)k];
        c->friction = sqrtf(ba->friction * bb->friction);
        c->dynamic_friction = sqrtf(ba->dynamic_friction * bb->dynamic_friction);
        c->restitution = ak_maxf(ba->restitution, bb->restitution);
        c->vn_before = c->restitution > 0.0f ? contact_vn(s, c) : 0.0f;
    }
    cb->count += (uint32_t)kept;
}

static bool joined(const ak_rigid_model* m, uint32_t a, uint32_t b);

static float axis_comp(ak_vec3 v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

static bool flat_shape(ak_rigid_shape_type t) { return t == AK_RIGID_BOX || t == AK_RIGID_PLANE; }

/* Relative normal velocity of contact c's points (before the solve; restitution reads it). */
RIGID_HOT float contact_vn(const solver* s, const rigid_contact* c) {
    ak_vec3 ra = ak_quat_rotate(s->q[c->a], c->la), rb = ak_quat_rotate(s->q[c->b], c->lb);
    ak_vec3 va = ak_vec3_add(s->v[c->a], ak_vec3_cross(s->w[c->a], ra));
    ak_vec3 vb = ak_vec3_add(s->v[c->b], ak_vec3_cross(s->w[c->b], rb));
    return ak_vec3_dot(c->n, ak_vec3_sub(va, vb));
}

typedef struct pair_buf {
    pair_entry* p;
    uint32_t count, cap;
    uint32_t dropped; /* pairs over cap */
} pair_buf;

/* Keep pair (a, b) for the step: a pair of flat shapes gets its contacts now, at the step's
 * start, with a margin that covers how far the two can close in the step (grow[a] + grow[b]),
 * and is dropped when it has none; any other pair is kept for the substeps' narrow phase. */
static void add_pair(solver* s, contact_buf* cb, pair_buf* pb, const float* grow, uint32_t a,
                     uint32_t b, float offset, ak_vec3 up) {
    if (pb->count >= pb->cap) {
        pb->dropped += 1;
        return;
    }
    pair_entry* e = &pb->p[pb->count];
    e->a = a;
    e->b = b;
    e->cached = flat_shape(s->bodies[a].shape.type) && flat_shape(s->bodies[b].shape.type);
    if (e->cached) {
        e->start = cb->count;
        narrow(s, cb, a, b, offset + grow[a] + grow[b]);
        e->end = cb->count;
        if (e->end == e->start) return;
    } else {
        e->start = e->end = cb->count;
    }
    ak_vec3 mid = s->bodies[b].shape.type == AK_RIGID_PLANE
                      ? s->x[a]
                      : ak_vec3_scale(ak_vec3_add(s->x[a], s->x[b]), 0.5f);
    /* in steps of the contact offset: pairs level to rounding (a layer of a pyramid) keep the
     * sweep's order rather than one their rounding noise picks */
    e->height = floorf(ak_vec3_dot(mid, up) / offset);
    pb->count++;
}

/* Whether body i's bounding sphere, grown by its step's reach, comes within the offset of
 * plane p. */
static bool plane_near(const solver* s, uint32_t i, uint32_t p, float offset, const float* grow) {
    const rigid_body* pl = &s->bodies[p];
    float dist = ak_vec3_dot(ak_vec3_sub(s->x[i], s->x[p]), pl->shape.normal);
    return !(dist - s->bodies[i].bound_radius > offset + grow[i]);
}

static bool pair_before(const pair_entry* a, const pair_entry* b) {
    return a->height > b->height || (a->height == b->height && a->start < b->start) ||
           (a->height == b->height && a->start == b->start &&
            (a->a < b->a || (a->a == b->a && a->b < b->b)));
}

/* The pairs of bodies the sweep sap[0 .. ns) overlaps, their motion margins scaled by scale
 * (1: the full test; see find_pairs). A pair of two awake bodies under the same gravity is
 * tested on their relative motion: gravity moves both alike and cancels, so the gap has to be
 * within the offset plus twice their relative speed times dt, plus each one's own travel dt |v|
 * (contacts can stop one of them within the step while the other goes on) and, for flat
 * shapes, their corners' turn (slack). A falling block of spheres then pairs each sphere with
 * the neighbours it can touch, not with every one within twice its own travel. */
static void body_pairs(solver* s, const sap_entry* sap, uint32_t ns, contact_buf* cb, pair_buf* pb,
                       const float* grow, const float* slack, float offset, float dt, ak_vec3 up,
                       float scale) {
    const ak_rigid_model* m = s->m;
    for (uint32_t i = 0; i < ns; ++i) {
        uint32_t a = sap[i].body;
        for (uint32_t j = i + 1; j < ns && sap[j].lo <= sap[i].hi; ++j) {
            uint32_t b = sap[j].body;
            if (!s->awake[a] && !s->awake[b]) continue;
            float rb = s->bodies[a].bound_radius + s->bodies[b].bound_radius + offset;
            float rr = rb + scale * (grow[a] + grow[b]);
            float d2 = ak_vec3_length_sq(ak_vec3_sub(s->x[a], s->x[b]));
            if (d2 > rr * rr) continue;
            if (s->awake[a] && s->awake[b]) {
                float rel = rb + scale * (2.0f * dt * ak_vec3_distance(s->v[a], s->v[b]) +
                                          slack[a] + slack[b]);
                if (d2 > rel * rel) continue;
            }
            if (s->bodies[a].group != 0 && s->bodies[a].group == s->bodies[b].group) continue;
            if (m->joint_count && joined(m, a, b)) continue;
            /* the awake (or lower-index) body first, so a static body is always b */
            if (!s->awake[a] || (s->awake[b] && b < a))
                add_pair(s, cb, pb, grow, b, a, offset, up);
            else
                add_pair(s, cb, pb, grow, a, b, offset, up);
        }
    }
}

/* Broad phase, once per step on the step's start poses: sweep and prune over bounding spheres
 * grown by the contact offset and by how far each body can move in the step (grow: twice its
 * speed times dt, plus what gravity adds, plus its corners' turn for flat shapes). Then the
 * pairs are ordered from the top down (against gravity; the found order when there is none):
 * in a stack or a pyramid the ground is then solved last, which lets a 10-box stack creep
 * several times less than bottom-up order. Shell sorts (no allocation, a total order). */
static void find_pairs(solver* s, sap_entry* sap, contact_buf* cb, pair_buf* pb, float* grow,
                       float* slack, const float* launch, float offset, float dt, float gmag,
                       ak_vec3 up, uint32_t* out_ns, int* out_axis) {
    const ak_rigid_model* m = s->m;
    uint32_t n = (uint32_t)m->body_count, ns = 0;
    cb->count = 0;
    pb->count = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const rigid_body* b = &s->bodies[i];
        grow[i] = slack[i] = 0.0f;
        if (!s->awake[i]) continue;
        float turn = flat_shape(b->shape.type) ? ak_vec3_length(s->w[i]) * b->bound_radius : 0.0f;
        grow[i] = 2.0f * dt * (ak_vec3_length(s->v[i]) + turn + launch[i]) + dt * dt * gmag;
        slack[i] = 2.0f * dt * (turn + launch[i]) + dt * ak_vec3_length(s->v[i]);
    }
    /* sweep along the axis over which the bodies spread most (their centres' variance) */
    double mean[3] = {0, 0, 0}, var[3] = {0, 0, 0};
    uint32_t counted = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (s->bodies[i].shape.type == AK_RIGID_PLANE) continue;
        ++counted;
        for (int k = 0; k < 3; ++k) {
            double x = axis_comp(s->x[i], k), d = x - mean[k];
            mean[k] += d / counted;
            var[k] += d * (x - mean[k]);
        }
    }
    int axis = var[1] > var[0] ? 1 : 0;
    if (var[2] > var[axis]) axis = 2;
    for (uint32_t i = 0; i < n; ++i) {
        const rigid_body* b = &s->bodies[i];
        if (b->shape.type == AK_RIGID_PLANE) continue;
        float r = b->bound_radius + offset + grow[i], c = axis_comp(s->x[i], axis);
        sap[ns].lo = c - r;
        sap[ns].hi = c + r;
        sap[ns].body = i;
        ++ns;
    }
    sap_sort(sap, ns);
    *out_ns = ns;
    *out_axis = axis;
    /* the pairs with planes (the walls and the ground) are kept first when the pairs overflow
     * max_contacts: room is held back for them while the bodies' pairs are found, so an
     * overflow drops pairs between bodies (they may sink into each other) but never lets a
     * body through the ground */
    uint32_t planes_near = 0;
    for (uint32_t i = 0; i < n && m->plane_count; ++i) {
        if (!s->awake[i]) continue;
        for (size_t k = 0; k < m->plane_count; ++k)
            planes_near += plane_near(s, i, m->planes[k], offset, grow);
    }
    uint32_t cap = pb->cap;
    pb->cap = planes_near < cap ? cap - planes_near : 0;
    /* when the bodies' pairs do not fit, the sweep runs again with the margins for the step's
     * motion at two thirds, one third, then none (the pairs within the contact offset now): the
     * pairs dropped are then the furthest apart, not the last ones the sweep met. The dropped
     * count is the full test's pairs that were not kept. */
    uint32_t wanted = 0, dropped0 = cb->dropped;
    for (int pass = 0; pass < 4; ++pass) {
        cb->count = 0;
        cb->dropped = dropped0;
        pb->count = 0;
        pb->dropped = 0;
        body_pairs(s, sap, ns, cb, pb, grow, slack, offset, dt, up, (float)(3 - pass) / 3.0f);
        if (pass == 0) wanted = pb->count + pb->dropped;
        if (pb->dropped == 0) break;
    }
    pb->dropped = wanted - pb->count;
    pb->cap = cap;
    for (uint32_t i = 0; i < n && m->plane_count; ++i) {
        if (!s->awake[i]) continue;
        for (size_t k = 0; k < m->plane_count; ++k)
            if (plane_near(s, i, m->planes[k], offset, grow)) {
                uint32_t before = pb->count;
                add_pair(s, cb, pb, grow, i, m->planes[k], offset, up);
                /* after an overflow the plane pairs are solved last in each substep: bodies the
                 * dropped pairs let sink into each other are pushed apart, and the last push on
                 * each is then the walls' and the ground's, which they end the solve outside of */
                if (pb->dropped && pb->count > before) pb->p[before].height = -INFINITY;
            }
    }
    cb->dropped += pb->dropped;
    /* bodies whose pairs were dropped can sink deep into each other, and pushing them apart in
     * one substep would throw them out at the depth over h (60 m/s for 10 cm at 600 Hz), past
     * the margins of their pairs with the walls: after an overflow a contact between two moving
     * bodies corrects at most 1 m/s times h per substep (contacts with static bodies and planes
     * in full) */
    if (pb->dropped) s->push_max = 1.0f * s->h;
    static const uint32_t gaps[] = {701, 301, 132, 57, 23, 10, 4, 1};
    pair_entry* e = pb->p;
    for (size_t gi = 0; gi < sizeof gaps / sizeof gaps[0]; ++gi) {
        uint32_t gap = gaps[gi];
        for (uint32_t i = gap; i < pb->count; ++i) {
            pair_entry t = e[i];
            uint32_t j = i;
            for (; j >= gap && pair_before(&t, &e[j - gap]); j -= gap) e[j] = e[j - gap];
            e[j] = t;
        }
    }
}

/* A substep's contacts, pair by pair in the step's order: the kept contacts of flat pairs
 * (their multipliers reset, their normal velocity read again) and the narrow phase of the
 * others on the predicted poses. */
static void substep_contacts(solver* s, contact_buf* cb, const pair_entry* pairs, uint32_t npairs,
                             uint32_t count0, float offset) {
    cb->count = count0;
    uint32_t g = 0;
    for (uint32_t i = 0; i < npairs; ++i) {
        const pair_entry* e = &pairs[i];
        if (e->cached) {
            for (uint32_t k = e->start; k < e->end; ++k) {
                rigid_contact* c = &cb->c[k];
                c->lambda_n = 0.0f;
                /* only restitution reads it */
                c->vn_before = c->restitution > 0.0f ? contact_vn(s, c) : 0.0f;
            }
            cb->groups[g++] = (contact_group){
                .start = e->start, .end = e->end, .height = e->height, .carry = e->carry,
                .carry_twist = e->carry_twist};
            continue;
        }
        /* bounding spheres apart by more than the offset now: nothing to find this substep */
        const rigid_body *ba = &s->bodies[e->a], *bb = &s->bodies[e->b];
        if (bb->shape.type != AK_RIGID_PLANE) {
            float rr = ba->bound_radius + bb->bound_radius + offset;
            if (ak_vec3_length_sq(ak_vec3_sub(s->x[e->a], s->x[e->b])) > rr * rr) continue;
        }
        uint32_t start = cb->count;
        narrow(s, cb, e->a, e->b, offset);
        if (cb->count > start) cb->groups[g++] =
                (contact_group){.start = start, .end = cb->count, .height = e->height};
    }
    cb->group_count = g;
}

RIGID_HOT ak_vec3 world_point(const solver* s, uint32_t i, ak_vec3 l) {
    return ak_vec3_add(s->x[i], ak_quat_rotate(s->q[i], l));
}

/* Centre of pressure of a group (the contacts' local points weighted by their normal
 * multipliers) in each body's frame, the group's total multiplier and the multipliers' mean
 * distance from the centre (the lever arm of torsional friction); false when no contact of the
 * group pushed. */
static bool pressure_centre(const contact_buf* cb, uint32_t k0, uint32_t k1, ak_vec3* la,
                            ak_vec3* lb, float* out_lambda, float* out_arm, uint32_t* out_points) {
    float sum = 0.0f, arm = 0.0f;
    uint32_t points = 0;
    ak_vec3 ca = ak_vec3_zero(), cbp = ak_vec3_zero();
    for (uint32_t k = k0; k < k1; ++k) {
        const rigid_contact* c = &cb->c[k];
        if (!(c->lambda_n > 0.0f)) continue;
        ++points;
        sum += c->lambda_n;
        ca = ak_vec3_madd(ca, c->la, c->lambda_n);
        cbp = ak_vec3_madd(cbp, c->lb, c->lambda_n);
    }
    if (!(sum > 0.0f)) return false;
    *la = ak_vec3_scale(ca, 1.0f / sum);
    *lb = ak_vec3_scale(cbp, 1.0f / sum);
    for (uint32_t k = k0; k < k1; ++k) {
        const rigid_contact* c = &cb->c[k];
        if (c->lambda_n > 0.0f) arm += c->lambda_n * ak_vec3_distance(c->la, *la);
    }
    *out_lambda = sum;
    *out_arm = arm / sum;
    *out_points = points;
    return true;
}

/* I^-1 n . n of body i (0 when it does not move). */
RIGID_HOT float gen_inv_inertia(const solver* s, uint32_t i, ak_vec3 n) {
    if (!s->awake[i]) return 0.0f;
    return ak_vec3_dot(n, ak_mat3_mul_vec3(s->iw[i], n));
}

/* Rotate body i by the angular position impulse (sign) * p (world). */
RIGID_HOT void apply_angular_impulse(solver* s, uint32_t i, ak_vec3 p, float sign) {
    if (!s->awake[i]) return;
    ak_vec3 dw = ak_vec3_scale(ak_mat3_mul_vec3(s->iw[i], p), sign * 0.5f);
    s->q[i] = turn_by(s->q[i], dw);
}

/* Motion of body i's local point l since the start of the step (the contact solve's pose, cx
 * and ct included), without the cancellation that (x + q l) - (x0 + q0 l) suffers far from the
 * origin; *out_arm gets its world offset. Static friction undoes the slip of the whole step,
 * not only of the substep: a slip left over by one substep (the next pair's solve moves a box
 * after its friction ran) is taken back by the next, so stacks do not creep. */
RIGID_HOT ak_vec3 moved_point(const solver* s, uint32_t i, ak_vec3 l, ak_vec3* out_arm) {
    ak_vec3 r = ak_mat3_mul_vec3(s->rot[i], l);
    r = ak_vec3_add(r, ak_vec3_cross(s->ct[i], r));
    *out_arm = r;
    if (!s->awake[i]) return ak_vec3_zero();
    ak_vec3 d = ak_vec3_add(s->ds[i], ak_vec3_add(s->dx[i], s->cx[i]));
    return ak_vec3_add(d, ak_vec3_sub(r, ak_mat3_mul_vec3(s->rot0[i], l)));
}

/* Whether body i is a sphere or a capsule: its points roll, however many a mesh reports. */
RIGID_HOT bool round_shape(const solver* s, uint32_t i) {
    ak_rigid_shape_type t = s->bodies[i].shape.type;
    return t == AK_RIGID_SPHERE || t == AK_RIGID_CAPSULE;
}

/* The part of arm r in the contact plane of normal n. */
RIGID_HOT ak_vec3 in_plane(ak_vec3 r, ak_vec3 n) { return ak_vec3_madd(r, n, -ak_vec3_dot(r, n)); }

/* The small-angle rotation vector that turns orientation from onto to (twice the vector part of
 * to from^-1, taken the short way). */
RIGID_HOT ak_vec3 small_turn(ak_quat to, ak_quat from) {
    ak_quat dq = ak_quat_mul(to, ak_quat_conjugate(from));
    float k = dq.w >= 0.0f ? 2.0f : -2.0f;
    return ak_vec3_make(dq.x * k, dq.y * k, dq.z * k);
}

/* Rotation vector of body i since the step's start, the contact solve's ct included (zero for
 * a body that does not move). */
RIGID_HOT ak_vec3 step_turn(const solver* s, uint32_t i) {
    return s->awake[i] ? ak_vec3_add(small_turn(s->q[i], s->q0[i]), s->ct[i]) : ak_vec3_zero();
}

/* Rotation vector of body i since the substep's start (small-angle), the contact solve's ct
 * included (zero for a body that does not move). */
RIGID_HOT ak_vec3 substep_turn(const solver* s, uint32_t i) {
    return s->awake[i] ? ak_vec3_add(small_turn(s->q[i], s->qp[i]), s->ct[i]) : ak_vec3_zero();
}

/* Motion since the step's start of body i's point at world arm r0 (at the step's start) of a
 * patch pair with normal n: the body's translation and its turn about n only. A face pressed on
 * a face over three or more points cannot tilt about an axis in the contact plane: the normal
 * rows hold that tilt, and any tilt the sequential solve leaves (one point pushed before the
 * next) is theirs to level. Counted as slip, the tilt moves the centre of pressure (half a box
 * below the centre of mass) sideways; static friction then shifts the box to cancel it, the
 * normal rows level the box by a pure rotation that leaves the shift, and the box walks: a
 * 20-layer pyramid spread 110 mm in 5 s at 10 substeps, 160 mm at mu 5, 54 mm at mu 0.2 (11 mm
 * with no static friction at all). Static friction on a patch therefore reads and moves only the
 * translation and the twist about n (the response uses the arm's in-plane part, whose cross
 * product with a tangent is along n): 21 mm. Two pushed points (a box resting on a support's
 * edge line) rock about that line the same way, and read whole they walked the pyramid still
 * (66 mm at 4 substeps): they are a patch too (10 mm; 1.9 mm at 10 substeps). Dynamic friction
 * reads the same motion only where static friction held on three or more points (on every
 * patch it took away the torque that tips a tall box sliding on a rough floor; on two points
 * the pyramid crept at 40 substeps and never slept), always with the whole arm in its
 * response. Spheres and capsules are never a
 * patch (a mesh reports several points of one touch), nor pairs with a body that does not move
 * (a box on a static slope near its friction cone crept under the rule). */
RIGID_HOT ak_vec3 patch_slip(const solver* s, uint32_t i, ak_vec3 l, ak_vec3 n) {
    if (!s->awake[i]) return ak_vec3_zero();
    ak_vec3 turn = step_turn(s, i);
    ak_vec3 r0 = ak_mat3_mul_vec3(s->rot0[i], l);
    ak_vec3 d = ak_vec3_add(s->ds[i], ak_vec3_add(s->dx[i], s->cx[i]));
    return ak_vec3_add(d, ak_vec3_scale(ak_vec3_cross(n, r0), ak_vec3_dot(turn, n)));
}

/* Rows of the substep's contacts on the current poses (see contact_row). */
static void setup_rows(solver* s, const contact_buf* cb) {
    for (uint32_t gi = 0; gi < cb->group_count; ++gi)
        for (uint32_t k = cb->groups[gi].start; k < cb->groups[gi].end; ++k) {
            const rigid_contact* c = &cb->c[k];
            contact_row* r = &s->rows[k];
            uint32_t a = c->a, b = c->b;
            ak_vec3 ra = ak_mat3_mul_vec3(s->rot[a], c->la),
                    rb = ak_mat3_mul_vec3(s->rot[b], c->lb);
            r->d0 =
                ak_vec3_dot(ak_vec3_sub(ak_vec3_add(s->x[b], rb), ak_vec3_add(s->x[a], ra)), c->n);
            float w = 0.0f;
            if (s->awake[a]) {
                r->rna = ak_vec3_cross(ra, c->n);
                r->ta = ak_mat3_mul_vec3(s->iw[a], r->rna);
                r->ima = s->bodies[a].inv_mass;
                w += r->ima + ak_vec3_dot(r->rna, r->ta);
            } else {
                r->rna = r->ta = ak_vec3_zero();
                r->ima = 0.0f;
            }
            if (s->awake[b]) {
                r->rnb = ak_vec3_cross(rb, c->n);
                r->tb = ak_mat3_mul_vec3(s->iw[b], r->rnb);
                r->imb = s->bodies[b].inv_mass;
                w += r->imb + ak_vec3_dot(r->rnb, r->tb);
            } else {
                r->rnb = r->tb = ak_vec3_zero();
                r->imb = 0.0f;
            }
            r->inv_w = w > 0.0f ? 1.0f / w : 0.0f;
        }
}

/* One pass over the normals of a group's contacts [k0, k1) (their eq. for the normal
 * multiplier, each push capped at push_max). Every contact of a group joins the same two
 * bodies: their corrections stay in registers over the group. */
static void solve_normals(solver* s, contact_buf* cb, uint32_t k0, uint32_t k1) {
    ak_vec3 *cx = s->cx, *ct = s->ct;
    uint32_t a = cb->c[k0].a, b = cb->c[k0].b;
    ak_vec3 cxa = cx[a], cta = ct[a], cxb = cx[b], ctb = ct[b];
    for (uint32_t k = k0; k < k1; ++k) {
        rigid_contact* c = &cb->c[k];
        const contact_row* r = &s->rows[k];
        float d = r->d0 + ak_vec3_dot(c->n, ak_vec3_sub(cxb, cxa)) + ak_vec3_dot(ctb, r->rnb) - ak_vec3_dot(cta, r->rna);
        if (d <= 0.0f || r->inv_w == 0.0f) continue;
        if (r->imb != 0.0f && d > s->push_max) d = s->push_max;
        float dl = d * r->inv_w;
        c->lambda_n += dl;
        /* (a body that does not move has a zero row: its sums stay zero) */
        cxa = ak_vec3_madd(cxa, c->n, dl * r->ima);
        cta = ak_vec3_madd(cta, r->ta, dl);
        cxb = ak_vec3_madd(cxb, c->n, -dl * r->imb);
        ctb = ak_vec3_madd(ctb, r->tb, -dl);
    }
    if (s->awake[a]) cx[a] = cxa, ct[a] = cta;
    if (s->awake[b]) cx[b] = cxb, ct[b] = ctb;
}

static void solve_positions(solver* s, contact_buf* cb, const uint32_t* list, uint32_t n) {
    ak_vec3 *cx = s->cx, *ct = s->ct;
    for (uint32_t t = 0; t < n; ++t) {
        uint32_t i = list ? list[t] : t;
        cx[i] = ct[i] = ak_vec3_zero();
        s->rot[i] = ak_mat3_from_quat(s->q[i]);
    }
    setup_rows(s, cb);
    for (uint32_t gi = 0; gi < cb->group_count; ++gi) {
        uint32_t k0 = cb->groups[gi].start, k1 = cb->groups[gi].end;
        /* (alternating the points' order from substep to substep halves a 10-box stack's creep
         * but moves the centre of pressure each substep, and a block on an incline then creeps:
         * the order stays fixed) */
        solve_normals(s, cb, k0, k1);
        /* static friction, once per pair at the centre of pressure with the pair's whole normal
         * multiplier: undo the relative tangential motion of this substep when the force it
         * takes stays inside the friction cone (their eq. for lambda_t < mu_s lambda_n); one
         * point per pair keeps the sequential order from handing the whole load to one corner */
        contact_group* grp = &cb->groups[gi];
        uint32_t points = 0;
        grp->pressed =
            pressure_centre(cb, k0, k1, &grp->la, &grp->lb, &grp->lambda, &grp->arm, &points);
        grp->patch = points >= 2 && s->awake[cb->c[k0].a] && s->awake[cb->c[k0].b] &&
                     !round_shape(s, cb->c[k0].a) && !round_shape(s, cb->c[k0].b);
        grp->stuck = 0;
        ak_vec3 la = grp->la, lb = grp->lb;
        float lambda = grp->lambda, arm = grp->arm;
        const rigid_contact* c = &cb->c[k0];
        uint32_t a = c->a, b = c->b;
        s->held[k0] = 0;
        if (!grp->pressed) continue;
        ak_vec3 ra, rb;
        ak_vec3 dp = ak_vec3_sub(moved_point(s, a, la, &ra), moved_point(s, b, lb, &rb));
        grp->ra = s->awake[a] ? ra : ak_vec3_zero();
        grp->rb = s->awake[b] ? rb : ak_vec3_zero();
        grp->wr = gen_inv_inertia(s, a, c->n) + gen_inv_inertia(s, b, c->n);
        if (c->friction > 0.0f) {
            /* (a patch: translation and twist only, see patch_slip) */
            if (grp->patch)
                dp = ak_vec3_sub(patch_slip(s, a, la, c->n), patch_slip(s, b, lb, c->n));

            /* (the anchors' drift from earlier steps, when the job keeps them) */
            dp = ak_vec3_add(dp, grp->carry);
            ak_vec3 dt = ak_vec3_madd(dp, c->n, -ak_vec3_dot(dp, c->n));
            float lt = ak_vec3_length(dt);
            grp->stuck = grp->patch && points >= 3;
            s->held[k0] = 1;
            if (lt > 1e-12f) {
                ak_vec3 t = ak_vec3_scale(dt, 1.0f / lt);
                response oa = respond(s, a, grp->patch ? in_plane(ra, c->n) : ra, t),
                         ob = respond(s, b, grp->patch ? in_plane(rb, c->n) : rb, t);
                float wt = oa.w + ob.w;
                float dlt = wt > 0.0f ? lt / wt : INFINITY;
                if (dlt < c->friction * lambda) {
                    if (s->awake[a]) {
                        cx[a] = ak_vec3_madd(cx[a], t, -dlt * s->bodies[a].inv_mass);
                        ct[a] = ak_vec3_madd(ct[a], oa.turn, -dlt);
                    }
                    if (s->awake[b]) {
                        cx[b] = ak_vec3_madd(cx[b], t, dlt * s->bodies[b].inv_mass);
                        ct[b] = ak_vec3_madd(ct[b], ob.turn, dlt);
                    }
                } else {
                    grp->stuck = 0, s->held[k0] = 0; /* it slid */
                }
            }
            /* torsional friction: a patch of contacts also resists twisting about the normal, up
             * to mu times the normal multiplier times its mean lever arm */
            /* (pairs of boxes and planes, which keep anchors, since the step's start, as their
             * static friction; the others, as before the anchors, since the substep's start:
             * reading a lying capsule's twist since the step's start sank CesiumMan's skinned
             * mesh 4.7 cm into the ground against 1.9) */
            ak_vec3 rot_a, rot_b;
            if (flat_shape(s->bodies[a].shape.type) && flat_shape(s->bodies[b].shape.type)) {
                rot_a = step_turn(s, a), rot_b = step_turn(s, b);
            } else {
                rot_a = substep_turn(s, a), rot_b = substep_turn(s, b);
            }
            float twist = ak_vec3_dot(ak_vec3_sub(rot_a, rot_b), c->n) + grp->carry_twist;
            float wr = grp->wr;
            if (wr > 0.0f && fabsf(twist) > 0.0f) {
                if (fabsf(twist) / wr < c->friction * lambda * arm) {
                    ak_vec3 pr = ak_vec3_scale(c->n, -twist / wr);
                    if (s->awake[a]) ct[a] = ak_vec3_add(ct[a], inv_inertia_mul(s, a, pr));
                    if (s->awake[b]) ct[b] = ak_vec3_sub(ct[b], inv_inertia_mul(s, b, pr));
                } else {
                    s->held[k0] = 0; /* the twist slipped */
                }
            }
        }
    }
    /* contact_iterations: more passes over the normals, on the same rows (friction and the
     * centres of pressure stay the first pass's) */
    for (uint32_t it = 1; it < s->m->desc.contact_iterations; ++it)
        for (uint32_t gi = 0; gi < cb->group_count; ++gi) solve_normals(s, cb, cb->groups[gi].start, cb->groups[gi].end);
    /* the summed corrections onto the poses (orientations normalised in update_velocities) */
    for (uint32_t t = 0; t < n; ++t) {
        uint32_t i = list ? list[t] : t;
        if (!s->awake[i]) continue;
        s->dx[i] = ak_vec3_add(s->dx[i], cx[i]);
        s->x[i] = ak_vec3_add(s->x0[i], ak_vec3_add(s->ds[i], s->dx[i]));
        ak_vec3 dw = ak_vec3_scale(ct[i], 0.5f);
        ak_quat q = s->q[i];
        s->q[i] = ak_quat_add(q, ak_quat_mul(ak_quat_make(dw.x, dw.y, dw.z, 0.0f), q));
    }
}

/* ---- joints (XPBD positional and angular constraints, Mueller et al. 2020, 3.3) ---------- */

/* Move anchor points pa (on a, offset ra) and pb (on b, offset rb) together by e = pb - pa
 * with compliance alpha (m/N), all three directions at once: the impulse p = K^-1 e with K =
 * (1/m_a + 1/m_b + alpha/h^2) 1 - [ra]x Ia^-1 [ra]x - [rb]x Ib^-1 [rb]x moves the anchors by
 * exactly e to first order. (Solving along e alone, as for a contact, turns a body whose
 * rotation is cheap about its centre: the anchor then also moves across e, and a pendulum of a
 * small ball on a long arm spins up 70 times too fast.) */
RIGID_HOT void joint_position(solver* s, uint32_t a, uint32_t b, ak_vec3 ra, ak_vec3 rb, ak_vec3 e,
                              float alpha, float* err) {
    if (ak_vec3_length_sq(e) < 1e-18f) return;
    *err = ak_maxf(*err, ak_vec3_length(e));
    float lin = (s->awake[a] ? s->bodies[a].inv_mass : 0.0f) +
                (s->awake[b] ? s->bodies[b].inv_mass : 0.0f) + alpha / (s->h * s->h);
    /* K is symmetric: its six entries, each body adding S I^-1 S^T (S = [r]x, rows s_i) */
    float k00 = lin, k01 = 0.0f, k02 = 0.0f, k11 = lin, k12 = 0.0f, k22 = lin;
    for (int side = 0; side < 2; ++side) {
        uint32_t i = side ? b : a;
        if (!s->awake[i]) continue;
        ak_vec3 r = side ? rb : ra;
        /* the rows s0 = (0, -z, y), s1 = (z, 0, -x), s2 = (-y, x, 0) times I^-1 and dotted
         * with each other, their zero entries' products left out: a product with zero only
         * adds an exact zero, which changes no sum but possibly an exact zero's sign, and
         * every entry below starts from +0 or from lin > 0, which erases that sign: the same
         * bits as the full products, in two thirds of the multiplications */
        const float* mm = s->iw[i].m;
        float x = r.x, y = r.y, z = r.z, nx = -r.x, ny = -r.y, nz = -r.z;
        ak_vec3 i0 = ak_vec3_make(mm[3] * nz + mm[6] * y, mm[4] * nz + mm[7] * y,
                                  mm[5] * nz + mm[8] * y);
        ak_vec3 i1 = ak_vec3_make(mm[0] * z + mm[6] * nx, mm[1] * z + mm[7] * nx,
                                  mm[2] * z + mm[8] * nx);
        ak_vec3 i2 = ak_vec3_make(mm[0] * ny + mm[3] * x, mm[1] * ny + mm[4] * x,
                                  mm[2] * ny + mm[5] * x);
        k00 += nz * i0.y + y * i0.z, k01 += nz * i1.y + y * i1.z, k02 += nz * i2.y + y * i2.z;
        k11 += z * i1.x + nx * i1.z, k12 += z * i2.x + nx * i2.z, k22 += ny * i2.x + x * i2.y;
    }
    /* p = K^-1 e by cofactors */
    float c00 = k11 * k22 - k12 * k12, c01 = k02 * k12 - k01 * k22, c02 = k01 * k12 - k02 * k11;
    float det = k00 * c00 + k01 * c01 + k02 * c02;
    if (!(fabsf(det) > 1e-30f) || !ak_finitef(det)) return;
    float c11 = k00 * k22 - k02 * k02, c12 = k01 * k02 - k00 * k12, c22 = k00 * k11 - k01 * k01;
    float id = 1.0f / det;
    ak_vec3 p = ak_vec3_make((c00 * e.x + c01 * e.y + c02 * e.z) * id,
                             (c01 * e.x + c11 * e.y + c12 * e.z) * id,
                             (c02 * e.x + c12 * e.y + c22 * e.z) * id);
    apply_position_impulse(s, a, ra, p, 1.0f);
    apply_position_impulse(s, b, rb, p, -1.0f);
}

/* Rotate a by (its share of) the rotation vector e and b by the opposite, so that a's frame
 * turns towards b's: lambda = |e| / (w_a + w_b + alpha / h^2), w = n^T I^-1 n. */
RIGID_HOT void joint_rotation(solver* s, uint32_t a, uint32_t b, ak_vec3 e, float alpha,
                              float* err) {
    float c = ak_vec3_length(e);
    if (c < 1e-9f) return;
    *err = ak_maxf(*err, c);
    ak_vec3 n = ak_vec3_scale(e, 1.0f / c);
    float w = gen_inv_inertia(s, a, n) + gen_inv_inertia(s, b, n) + alpha / (s->h * s->h);
    if (!(w > 0.0f)) return;
    ak_vec3 p = ak_vec3_scale(n, c / w);
    apply_angular_impulse(s, a, p, 1.0f);
    apply_angular_impulse(s, b, p, -1.0f);
}

/* The rotation vector that turns a's frame times target onto b's orientation. */
RIGID_HOT ak_vec3 orientation_error(ak_quat qa, ak_quat qb, ak_quat target) {
    return small_turn(qb, ak_quat_mul(qa, target));
}

/* True when ball joint j's twist is inside its limits by at least 1e-4 rad (without the angle:
 * akp_rigid_twist_angle's half angle t/2 = atan2(y, w) of rel, taken with w >= 0, lies
 * between the limits' half angles L and H when sin(t/2 - L) and sin(H - t/2) are positive,
 * which needs no atan2); false also when it cannot tell (twist_fast off). */
RIGID_HOT bool twist_inside(const rigid_joint* j, ak_quat qa, ak_quat qb) {
    if (!j->twist_fast) return false;
    ak_quat rel =
        ak_quat_mul(ak_quat_conjugate(ak_quat_mul(qa, j->frame_a)), ak_quat_mul(qb, j->frame_b));
    float y = rel.w < 0.0f ? -rel.y : rel.y, w = fabsf(rel.w);
    float r = sqrtf(y * y + w * w);
    if (!(r > 1e-6f)) return false;
    return y * j->twist_cl - w * j->twist_sl > 1e-4f * r &&
           w * j->twist_sh - y * j->twist_ch > 1e-4f * r;
}

/* One sweep over the joints idx[0 .. count) (NULL idx: every joint in model order); *err gets
 * the largest correction (m or rad). */
static void solve_joints(solver* s, const uint32_t* idx, uint32_t count, float* err) {
    const ak_rigid_model* m = s->m;
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t k = idx ? idx[i] : i;
        const rigid_joint* j = &m->joints[k];
        uint32_t a = j->a, b = j->b;
        if (!s->awake[a] && !s->awake[b]) continue;
        float alpha = j->compliance;
        /* the anchors first, then the orientation parts (limits last, so a sweep ends with
         * them met: anchors moved by a limit's pure rotation come back in the next sweep) */
        ak_vec3 ra = ak_quat_rotate(s->q[a], j->la), rb = ak_quat_rotate(s->q[b], j->lb);
        ak_vec3 e = ak_vec3_sub(ak_vec3_add(s->x[b], rb), ak_vec3_add(s->x[a], ra));
        if (j->type == AK_RIGID_JOINT_PRISMATIC) {
            ak_vec3 ax = ak_quat_rotate(s->q[a], j->axis_a);
            float off = ak_vec3_dot(e, ax);
            float keep = j->limited ? ak_clampf(off, j->lower, j->upper) : off;
            e = ak_vec3_madd(e, ax, -keep);
        }
        joint_position(s, a, b, ra, rb, e, alpha, err);
        if (j->type == AK_RIGID_JOINT_FIXED || j->type == AK_RIGID_JOINT_PRISMATIC)
            joint_rotation(s, a, b, orientation_error(s->q[a], s->q[b], j->rel), alpha, err);
        if (j->type == AK_RIGID_JOINT_HINGE) {
            ak_vec3 a1 = ak_quat_rotate(s->q[a], j->axis_a),
                    a2 = ak_quat_rotate(s->q[b], j->axis_b);
            joint_rotation(s, a, b, ak_vec3_cross(a1, a2), alpha, err);
            if (j->limited) {
                float phi = akp_rigid_hinge_angle(j, s->q[a], s->q[b]) + j->angle_offset;
                float target = ak_clampf(phi, j->lower, j->upper);
                if (phi != target)
                    joint_rotation(s, a, b,
                                   ak_vec3_scale(ak_quat_rotate(s->q[a], j->axis_a), phi - target),
                                   0.0f, err);
            }
        }
        if (j->type == AK_RIGID_JOINT_BALL && j->limited) {
            ak_vec3 a1 = ak_quat_rotate(s->q[a], j->axis_a),
                    a2 = ak_quat_rotate(s->q[b], j->axis_b);
            float cs = ak_vec3_dot(a1, a2);
            /* the angle only when not well inside the cone (the orientations are unit to well
             * under 1e-3 within a substep, so cs is the swing's cosine within 1e-3) */
            if (!(cs > j->cos_upper + 1e-3f)) {
                ak_vec3 cr = ak_vec3_cross(a1, a2);
                float sn = ak_vec3_length(cr), swing = atan2f(sn, cs);
                if (swing > j->upper && sn > 1e-9f)
                    joint_rotation(s, a, b, ak_vec3_scale(cr, (swing - j->upper) / sn), 0.0f, err);
            }
        }
        if (j->type == AK_RIGID_JOINT_BALL && j->twist_limited &&
            !twist_inside(j, s->q[a], s->q[b])) {
            ak_vec3 n;
            float tw = akp_rigid_twist_angle(j, s->q[a], s->q[b], &n) + j->angle_offset;
            float target = ak_clampf(tw, j->twist_lower, j->twist_upper);
            if (tw != target) joint_rotation(s, a, b, ak_vec3_scale(n, tw - target), 0.0f, err);
        }
        if (j->drive && j->type != AK_RIGID_JOINT_FIXED && j->type != AK_RIGID_JOINT_PRISMATIC)
            joint_rotation(s, a, b,
                           orientation_error(s->q[a], s->q[b],
                                             s->drive_targets
                                                 ? ak_quat_normalize(s->drive_targets[k])
                                                 : j->drive_target),
                           j->drive_compliance, err);
    }
}

/* True when bodies a and b are joined (jointed bodies do not collide with each other). */
static bool joined(const ak_rigid_model* m, uint32_t a, uint32_t b) {
    for (size_t k = 0; k < m->joint_count; ++k) {
        const rigid_joint* j = &m->joints[k];
        if ((j->a == a && j->b == b) || (j->a == b && j->b == a)) return true;
    }
    return false;
}

/* Drive damping: remove the fraction min(c h, 1) of each driven joint's relative angular
 * velocity with an equal and opposite angular impulse (momentum kept). */
static void damp_drives(solver* s, const uint32_t* idx, uint32_t count) {
    const ak_rigid_model* m = s->m;
    for (uint32_t i = 0; i < count; ++i) {
        const rigid_joint* j = &m->joints[idx ? idx[i] : i];
        if (!j->drive || !(j->drive_damping > 0.0f)) continue;
        uint32_t a = j->a, b = j->b;
        if (!s->awake[a] && !s->awake[b]) continue;
        ak_vec3 dw = ak_vec3_sub(s->w[b], s->w[a]);
        float c = ak_vec3_length(dw);
        if (c < 1e-9f) continue;
        ak_vec3 n = ak_vec3_scale(dw, 1.0f / c);
        float wsum = gen_inv_inertia(s, a, n) + gen_inv_inertia(s, b, n);
        if (!(wsum > 0.0f)) continue;
        ak_vec3 p = ak_vec3_scale(n, c * ak_minf(j->drive_damping * s->h, 1.0f) / wsum);
        /* (a static body is left alone: islands share them) */
        if (s->bodies[a].inv_mass > 0.0f) s->w[a] = ak_vec3_add(s->w[a], inv_inertia_mul(s, a, p));
        if (s->bodies[b].inv_mass > 0.0f) s->w[b] = ak_vec3_sub(s->w[b], inv_inertia_mul(s, b, p));
    }
}

static void update_velocities(solver* s, const uint32_t* list, uint32_t count) {
    float inv_h = 1.0f / s->h;
    for (uint32_t t = 0; t < count; ++t) {
        uint32_t i = list ? list[t] : t;
        if (!s->awake[i]) continue;
        s->v[i] = ak_vec3_scale(s->dx[i], inv_h);
        s->ds[i] = ak_vec3_add(s->ds[i], s->dx[i]);
        s->q[i] = ak_quat_normalize(s->q[i]);
        /* predict's q' = normalise((1 + h/2 [w, 0]) q) gives dq = q' q^-1 with dq.xyz / dq.w =
         * h w / 2 exactly, so this inverse returns w unchanged when no constraint acted (2 dq.xyz
         * / h alone loses w (w h)^2 / 8 per substep: 5% of a spin's momentum in 10 s) */
        ak_quat dq = ak_quat_mul(s->q[i], ak_quat_conjugate(s->qp[i]));
        float sg = 2.0f * inv_h / (fabsf(dq.w) > 0.1f ? dq.w : (dq.w >= 0.0f ? 0.1f : -0.1f));
        s->w[i] = ak_vec3_make(dq.x * sg, dq.y * sg, dq.z * sg);
    }
}

RIGID_HOT ak_vec3 point_velocity(const solver* s, uint32_t i, ak_vec3 r) {
    return ak_vec3_add(s->v[i], ak_vec3_cross(s->w[i], r));
}

/* Velocity of body i's point at in-plane arm r of a patch (normal n): its linear velocity and its
 * spin about n only (see patch_slip); zero for a body that does not move. */
RIGID_HOT ak_vec3 patch_velocity(const solver* s, uint32_t i, ak_vec3 r, ak_vec3 n) {
    if (!s->awake[i]) return ak_vec3_zero();
    return ak_vec3_add(s->v[i], ak_vec3_scale(ak_vec3_cross(n, r), ak_vec3_dot(s->w[i], n)));
}

static void solve_velocities(solver* s, contact_buf* cb, float gmag) {
    float h = s->h;
    /* velocity_iterations: passes over the normals before the last (Gauss-Seidel, in the pairs'
     * top-down order). One pass hands a pile's velocities down one contact at a time: in a
     * 20-layer pyramid at rest the velocities of the position solve's pushes (v = dx / h, about g
     * h) are left at 0.03-0.08 m/s and it never sleeps; 4 passes leave 0.005-0.016 m/s. */
    for (uint32_t it = 1; it < s->m->desc.velocity_iterations; ++it)
        for (uint32_t gi = 0; gi < cb->group_count; ++gi) {
            /* every contact of a group joins the same two bodies: their velocities stay in
             * registers over the group */
            uint32_t k0 = cb->groups[gi].start, k1 = cb->groups[gi].end;
            uint32_t a = cb->c[k0].a, b = cb->c[k0].b;
            ak_vec3 va = s->v[a], wa = s->w[a], vb = s->v[b], wb = s->w[b];
            for (uint32_t k = k0; k < k1; ++k) {
                const rigid_contact* c = &cb->c[k];
                const contact_row* r = &s->rows[k];
                if (!(c->lambda_n > 0.0f) || r->inv_w == 0.0f) continue;
                float vn = ak_vec3_dot(c->n, ak_vec3_sub(va, vb)) + ak_vec3_dot(wa, r->rna) -
                           ak_vec3_dot(wb, r->rnb);
                float e = fabsf(c->vn_before) <= 2.0f * gmag * h ? 0.0f : c->restitution;
                float mag = (-vn + ak_maxf(-e * c->vn_before, 0.0f)) * r->inv_w;
                /* (a body that does not move has a zero row: its velocities stay) */
                va = ak_vec3_madd(va, c->n, mag * r->ima);
                wa = ak_vec3_madd(wa, r->ta, mag);
                vb = ak_vec3_madd(vb, c->n, -mag * r->imb);
                wb = ak_vec3_madd(wb, r->tb, -mag);
            }
            if (s->awake[a]) s->v[a] = va, s->w[a] = wa;
            if (s->awake[b]) s->v[b] = vb, s->w[b] = wb;
        }
    for (uint32_t gi = 0; gi < cb->group_count; ++gi) {
        uint32_t k0 = cb->groups[gi].start, k1 = cb->groups[gi].end;
        for (uint32_t k = k0; k < k1; ++k) {
            const rigid_contact* c = &cb->c[k];
            if (!(c->lambda_n > 0.0f)) continue;
            const contact_row* r = &s->rows[k];
            uint32_t a = c->a, b = c->b;
            /* n . (v + w x r) = n . v + w . (r x n), the arms of the position solve's rows */
            float vn = ak_vec3_dot(c->n, ak_vec3_sub(s->v[a], s->v[b])) +
                       ak_vec3_dot(s->w[a], r->rna) - ak_vec3_dot(s->w[b], r->rnb);
            /* restitution: the normal velocity becomes -e times the one before the solve (none
             * for slow impacts, which gravity alone could have made in two substeps) */
            float e = fabsf(c->vn_before) <= 2.0f * gmag * h ? 0.0f : c->restitution;
            float dvn = -vn + ak_maxf(-e * c->vn_before, 0.0f);
            if (fabsf(dvn) < 1e-12f || r->inv_w == 0.0f) continue;
            float mag = dvn * r->inv_w;
            if (r->ima > 0.0f) {
                s->v[a] = ak_vec3_madd(s->v[a], c->n, mag * r->ima);
                s->w[a] = ak_vec3_madd(s->w[a], r->ta, mag);
            }
            if (r->imb > 0.0f) {
                s->v[b] = ak_vec3_madd(s->v[b], c->n, -mag * r->imb);
                s->w[b] = ak_vec3_madd(s->w[b], r->tb, -mag);
            }
        }
        /* dynamic friction at the centre of pressure (their eq. 30 with the units made whole) */
        const contact_group* grp = &cb->groups[gi];
        float lambda = grp->lambda, arm = grp->arm;
        const rigid_contact* c = &cb->c[k0];
        if (c->dynamic_friction > 0.0f && grp->pressed) {
            ak_vec3 ra = grp->ra, rb = grp->rb;
            ak_vec3 vr = ak_vec3_sub(point_velocity(s, c->a, ra), point_velocity(s, c->b, rb));
            if (grp->stuck) {
                /* a patch its static friction held: the translation and the spin about n only,
                 * as there (patch_slip); a sliding one keeps the whole arm, whose torque tips a
                 * tall box */
                ra = in_plane(ra, c->n);
                rb = in_plane(rb, c->n);
                vr = ak_vec3_sub(patch_velocity(s, c->a, ra, c->n),
                                 patch_velocity(s, c->b, rb, c->n));
            }
            ak_vec3 vt = ak_vec3_madd(vr, c->n, -ak_vec3_dot(vr, c->n));
            float lt = ak_vec3_length(vt);
            if (lt > 1e-12f) {
                /* the friction impulse is at most mu_d times the normal one, lambda_n / h; as a
                 * change of relative velocity that is mu_d lambda_n w_t / h */
                ak_vec3 t = ak_vec3_scale(vt, 1.0f / lt);
                response oa = respond(s, c->a, ra, t), ob = respond(s, c->b, rb, t);
                float wt = oa.w + ob.w;
                float cut = ak_minf(c->dynamic_friction * lambda * wt / h, lt);
                if (wt > 0.0f) {
                    push_along(s, c->a, t, -cut / wt, oa);
                    push_along(s, c->b, t, cut / wt, ob);
                }
            }
            float spin = ak_vec3_dot(ak_vec3_sub(s->w[c->a], s->w[c->b]), c->n);
            float wr = grp->wr;
            if (wr > 0.0f && spin != 0.0f) {
                float cut = ak_minf(c->dynamic_friction * lambda * arm * wr / h, fabsf(spin));
                ak_vec3 pr = ak_vec3_scale(c->n, (spin > 0.0f ? -cut : cut) / wr);
                if (s->awake[c->a])
                    s->w[c->a] = ak_vec3_add(s->w[c->a], inv_inertia_mul(s, c->a, pr));
                if (s->awake[c->b])
                    s->w[c->b] = ak_vec3_sub(s->w[c->b], inv_inertia_mul(s, c->b, pr));
            }
        }
    }
}

/* ak_rigid_model_desc.contacts_after_joints: one Gauss-Seidel pass over the substep's contacts
 * on the current poses (after the joint sweeps), each pushed out along its normal by its exact
 * depth (the lever arms of the current orientations, not the rows': the joints have turned the
 * bodies since), its multiplier raised by the push so the velocity solve treats it as pressed.
 * Normal only: static friction stays the position solve's. */
static void contacts_after_joints(solver* s, contact_buf* cb) {
    for (uint32_t gi = 0; gi < cb->group_count; ++gi)
        for (uint32_t k = cb->groups[gi].start; k < cb->groups[gi].end; ++k) {
            rigid_contact* c = &cb->c[k];
            uint32_t a = c->a, b = c->b;
            if (!s->awake[a] && !s->awake[b]) continue;
            ak_vec3 ra = ak_quat_rotate(s->q[a], c->la), rb = ak_quat_rotate(s->q[b], c->lb);
            float d =
                ak_vec3_dot(ak_vec3_sub(ak_vec3_add(s->x[b], rb), ak_vec3_add(s->x[a], ra)), c->n);
            if (!(d > 0.0f)) continue;
            if (s->awake[b] && d > s->push_max) d = s->push_max; /* (see find_pairs) */
            response oa = respond(s, a, ra, c->n), ob = respond(s, b, rb, c->n);
            float w = oa.w + ob.w;
            if (!(w > 0.0f)) continue;
            float dl = d / w;
            c->lambda_n += dl;
            ak_vec3 p = ak_vec3_scale(c->n, dl);
            apply_position_impulse(s, a, ra, p, 1.0f);
            apply_position_impulse(s, b, rb, p, -1.0f);
        }
}

static uint32_t uf_find(uint32_t* parent, uint32_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Joints grouped into chains: the joints that share moving bodies (union-find over the joints
 * between two dynamic bodies; a static body links nothing, since it never moves), each chain's
 * joints in model order, chains in the order of their first joint: order[start[c] ..
 * start[c + 1]) are chain c's. No body moved by one chain is moved by another, so sweeping the
 * chains one after another gives the same numbers as sweeping the joints in model order, and
 * the chains may be swept in any order or at the same time. chain_of gets each joint's chain
 * (scratch). Returns the chain count. */
static uint32_t joint_chains(const solver* s, uint32_t* parent, uint32_t* root_chain,
                             uint32_t* chain_of, uint32_t* order, uint32_t* start) {
    const ak_rigid_model* m = s->m;
    uint32_t n = (uint32_t)m->body_count, nj = (uint32_t)m->joint_count, chains = 0;
    for (uint32_t i = 0; i < n; ++i) parent[i] = i, root_chain[i] = UINT32_MAX;
    for (uint32_t k = 0; k < nj; ++k) {
        uint32_t a = m->joints[k].a, b = m->joints[k].b;
        if (s->bodies[a].inv_mass == 0.0f || s->bodies[b].inv_mass == 0.0f) continue;
        uint32_t ra = uf_find(parent, a), rb = uf_find(parent, b);
        if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
    }
    for (uint32_t c = 0; c <= nj; ++c) start[c] = 0;
    for (uint32_t k = 0; k < nj; ++k) {
        uint32_t a = m->joints[k].a;
        uint32_t r = uf_find(parent, s->bodies[a].inv_mass > 0.0f ? a : m->joints[k].b);
        if (root_chain[r] == UINT32_MAX) root_chain[r] = chains++;
        chain_of[k] = root_chain[r];
        start[chain_of[k] + 1]++;
    }
    for (uint32_t c = 0; c < chains; ++c) start[c + 1] += start[c];
    /* stable placement; root_chain is free again: a cursor per chain */
    for (uint32_t c = 0; c < chains; ++c) root_chain[c] = start[c];
    for (uint32_t k = 0; k < nj; ++k) order[root_chain[chain_of[k]]++] = k;
    return chains;
}

/* The joint sweeps after the contacts: each chain swept up to `sweeps` times, stopping once a
 * sweep corrects none of its joints by more than 0.1 mm or 0.1 mrad (a chain at rest stops
 * after one while a falling one goes on). */
typedef struct chain_task {
    solver* s;
    const uint32_t *order, *start;
    uint32_t c0, c1; /* chains [c0, c1) */
    int sweeps;
} chain_task;

static void* sweep_chains(void* arg) {
    const chain_task* t = arg;
    for (uint32_t c = t->c0; c < t->c1; ++c) {
        const uint32_t* idx = t->order + t->start[c];
        uint32_t count = t->start[c + 1] - t->start[c];
        for (int it = 0; it < t->sweeps; ++it) {
            float err = 0.0f;
            solve_joints(t->s, idx, count, &err);
            if (err < t->s->m->desc.joint_tolerance) break;
        }
    }
    return NULL;
}

/* Sweep the chains list[0 .. count) (see chain_task). */
static void sweep_chain_list(solver* s, const uint32_t* order, const uint32_t* start,
                             const uint32_t* list, uint32_t count, int sweeps) {
    for (uint32_t t = 0; t < count; ++t) {
        uint32_t c = list[t];
        const uint32_t* idx = order + start[c];
        uint32_t n = start[c + 1] - start[c];
        for (int it = 0; it < sweeps; ++it) {
            float err = 0.0f;
            solve_joints(s, idx, n, &err);
            if (err < s->m->desc.joint_tolerance) break;
        }
    }
}

/* Contact points a non-cached pair can give in a substep: one for a sphere against a sphere,
 * a plane or a box (closed forms), else AKP_RIGID_MAX_PAIR_CONTACTS. */
static uint32_t pair_bound(const rigid_body* ba, const rigid_body* bb) {
    if (ba->compound || bb->compound || ba->mesh || bb->mesh) return AKP_RIGID_MAX_PAIR_CONTACTS;
    ak_rigid_shape_type ta = ba->shape.type, tb = bb->shape.type;
    if (ta == AK_RIGID_SPHERE &&
        (tb == AK_RIGID_SPHERE || tb == AK_RIGID_PLANE || tb == AK_RIGID_BOX))
        return 1;
    if (tb == AK_RIGID_SPHERE && (ta == AK_RIGID_PLANE || ta == AK_RIGID_BOX)) return 1;
    return AKP_RIGID_MAX_PAIR_CONTACTS;
}

/* What an island task needs: the islands [i0, i1) solved one after another, every substep of
 * one before the next. */
typedef struct island_task {
    solver* s;
    island* isl;
    uint32_t i0, i1;
    const uint32_t *ibodies, *ijoints, *ichains, *order, *start;
    const pair_entry* ipairs;
    rigid_contact* c;
    contact_group* groups;
    ak_vec3 gravity;
    float offset, gmag;
    uint32_t substeps;
} island_task;

static void* solve_islands(void* arg) {
    const island_task* t = arg;
    solver* s = t->s;
    const ak_rigid_model_desc* d = &s->m->desc;
    for (uint32_t ii = t->i0; ii < t->i1; ++ii) {
        island* is = &t->isl[ii];
        if (!is->awake) continue; /* nothing moves: no pair, its joints skipped */
        const uint32_t* bodies = t->ibodies + is->body0;
        uint32_t nb = is->body1 - is->body0;
        const uint32_t* joints = t->ijoints + is->joint0;
        uint32_t nj = is->joint1 - is->joint0;
        contact_buf cb = {t->c, is->region, is->region_end, 0, t->groups + is->pair0, 0};
        for (uint32_t step = 0; step < t->substeps; ++step) {
            predict(s, t->gravity, d->linear_damping, d->angular_damping, bodies, nb);
            substep_contacts(s, &cb, t->ipairs + is->pair0, is->pair1 - is->pair0, is->region,
                             t->offset);
            if (nj) {
                float err = 0.0f;
                solve_joints(s, joints, nj, &err);
            }
            solve_positions(s, &cb, bodies, nb);
            sweep_chain_list(s, t->order, t->start, t->ichains + is->chain0,
                             is->chain1 - is->chain0, 8);
            if (d->contacts_after_joints) contacts_after_joints(s, &cb);
            update_velocities(s, bodies, nb);
            damp_drives(s, joints, nj);
            solve_velocities(s, &cb, t->gmag);
        }
        is->count_last = cb.count - is->region;
        is->dropped = cb.dropped;
    }
    return NULL;
}

/* The step's islands (see island) into isl, their lists into ibodies, ipairs, ijoints and
 * ichains (chains from joint_chains); the regions of the contact buffer follow its cached
 * contacts, [0, kept). Returns the island count, or 0 when every pair's region does not fit in
 * cap contacts (the caller then solves one island). parent and island_of are scratch. */
static uint32_t build_islands(const solver* s, const pair_buf* pb, uint32_t kept, uint32_t cap,
                              uint32_t chains, const uint32_t* order, const uint32_t* start,
                              uint32_t* parent, uint32_t* island_of, uint32_t* ibodies,
                              pair_entry* ipairs, uint32_t* ijoints, uint32_t* ichains,
                              island* isl) {
    const ak_rigid_model* m = s->m;
    const rigid_body* bd = s->bodies;
    uint32_t n = (uint32_t)m->body_count, nj = (uint32_t)m->joint_count, count = 0;
    /* the region bound first: nothing else is needed when it does not fit */
    uint64_t need = kept;
    for (uint32_t k = 0; k < pb->count; ++k)
        if (!pb->p[k].cached) need += pair_bound(&bd[pb->p[k].a], &bd[pb->p[k].b]);
    if (need > cap) return 0;
    for (uint32_t i = 0; i < n; ++i) parent[i] = i;
    for (uint32_t k = 0; k < pb->count; ++k) {
        uint32_t a = pb->p[k].a, b = pb->p[k].b;
        if (bd[a].inv_mass == 0.0f || bd[b].inv_mass == 0.0f) continue;
        uint32_t ra = uf_find(parent, a), rb = uf_find(parent, b);
        if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
    }
    for (uint32_t k = 0; k < nj; ++k) {
        uint32_t a = m->joints[k].a, b = m->joints[k].b;
        if (bd[a].inv_mass == 0.0f || bd[b].inv_mass == 0.0f) continue;
        uint32_t ra = uf_find(parent, a), rb = uf_find(parent, b);
        if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
    }
    /* islands numbered by their lowest body (every root is its set's lowest index) */
    for (uint32_t i = 0; i < n; ++i) {
        island_of[i] = UINT32_MAX;
        if (bd[i].inv_mass == 0.0f) continue;
        uint32_t r = uf_find(parent, i);
        if (r == i) {
            isl[count] = (island){0};
            island_of[i] = count++;
        } else {
            island_of[i] = island_of[r];
        }
        island* is = &isl[island_of[i]];
        is->body1++;
        is->awake = is->awake || s->awake[i];
    }
    for (uint32_t k = 0; k < pb->count; ++k) {
        island* is = &isl[island_of[pb->p[k].a]]; /* a moves */
        is->pair1++;
        if (!pb->p[k].cached) is->region_end += pair_bound(&bd[pb->p[k].a], &bd[pb->p[k].b]);
    }
    for (uint32_t k = 0; k < nj; ++k) {
        uint32_t a = m->joints[k].a, b = m->joints[k].b;
        uint32_t i = bd[a].inv_mass > 0.0f ? a : b;
        if (bd[i].inv_mass > 0.0f) isl[island_of[i]].joint1++;
    }
    for (uint32_t c = 0; c < chains; ++c) {
        const rigid_joint* j = &m->joints[order[start[c]]];
        uint32_t i = bd[j->a].inv_mass > 0.0f ? j->a : j->b;
        if (bd[i].inv_mass > 0.0f) isl[island_of[i]].chain1++;
    }
    /* counts to runs */
    uint32_t nb = 0, np = 0, nk = 0, nc = 0, region = kept;
    for (uint32_t k = 0; k < count; ++k) {
        island* is = &isl[k];
        uint32_t cb = is->body1, cp = is->pair1, ck = is->joint1, cc = is->chain1,
                 cr = is->region_end;
        is->work = is->awake ? cb + 2 * cp + 3 * ck : 0;
        is->body0 = is->body1 = nb, nb += cb;
        is->pair0 = is->pair1 = np, np += cp;
        is->joint0 = is->joint1 = nk, nk += ck;
        is->chain0 = is->chain1 = nc, nc += cc;
        is->region = region, region += cr;
        is->region_end = region;
    }
    /* stable placement: each island's lists in the global order */
    for (uint32_t i = 0; i < n; ++i)
        if (bd[i].inv_mass > 0.0f) ibodies[isl[island_of[i]].body1++] = i;
    for (uint32_t k = 0; k < pb->count; ++k) ipairs[isl[island_of[pb->p[k].a]].pair1++] = pb->p[k];
    for (uint32_t k = 0; k < nj; ++k) {
        uint32_t a = m->joints[k].a, b = m->joints[k].b;
        uint32_t i = bd[a].inv_mass > 0.0f ? a : b;
        if (bd[i].inv_mass > 0.0f) ijoints[isl[island_of[i]].joint1++] = k;
    }
    for (uint32_t c = 0; c < chains; ++c) {
        const rigid_joint* j = &m->joints[order[start[c]]];
        uint32_t i = bd[j->a].inv_mass > 0.0f ? j->a : j->b;
        if (bd[i].inv_mass > 0.0f) ichains[isl[island_of[i]].chain1++] = c;
    }
    return count;
}

/* Sleep bookkeeping at the end of a step (see ak_rigid_step_job.sleep_timers). */
static void update_sleep(solver* s, const ak_rigid_step_job* job, const contact_buf* cb,
                         uint32_t* parent) {
    const ak_rigid_model_desc* d = &s->m->desc;
    uint32_t n = (uint32_t)s->m->body_count;
    float* timer = job->sleep_timers.ptr;
    for (uint32_t i = 0; i < n; ++i) {
        parent[i] = i;
        if (!s->awake[i]) continue;
        bool slow = ak_vec3_length(s->v[i]) < d->sleep_linear_speed &&
                    ak_vec3_length(s->w[i]) < d->sleep_angular_speed;
        timer[i] = slow ? timer[i] + job->dt : 0.0f;
    }
    for (uint32_t k = 0; k < cb->count; ++k) {
        uint32_t a = cb->c[k].a, b = cb->c[k].b;
        if (s->bodies[a].inv_mass == 0.0f || s->bodies[b].inv_mass == 0.0f) continue;
        uint32_t ra = uf_find(parent, a), rb = uf_find(parent, b);
        if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
    }
    for (size_t k = 0; k < s->m->joint_count; ++k) {
        uint32_t a = s->m->joints[k].a, b = s->m->joints[k].b;
        if (s->bodies[a].inv_mass == 0.0f || s->bodies[b].inv_mass == 0.0f) continue;
        uint32_t ra = uf_find(parent, a), rb = uf_find(parent, b);
        if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
    }
    /* a group sleeps when its least sleepy body has been slow long enough; otherwise every
     * body of it is awake. Roots hold the group's minimum timer in a second pass. */
    for (uint32_t i = 0; i < n; ++i) {
        if (s->bodies[i].inv_mass == 0.0f) continue;
        uint32_t r = uf_find(parent, i);
        if (r != i && timer[i] < timer[r]) timer[r] = timer[i];
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (s->bodies[i].inv_mass == 0.0f) continue;
        uint32_t r = uf_find(parent, i);
        if (timer[r] >= d->sleep_time) {
            s->v[i] = ak_vec3_zero();
            s->w[i] = ak_vec3_zero();
            if (timer[i] < d->sleep_time) timer[i] = d->sleep_time;
        } else if (!s->awake[i]) {
            timer[i] = 0.0f; /* asleep at the step's start, touched by a moving group: wake */
        } else if (timer[i] >= d->sleep_time) {
            /* slow long enough itself, but its group is not: the next step reads a timer at
             * sleep_time as asleep, so it stays just under (frozen alone for a step while its
             * group moved on, then woken at zero, the bottom boxes of a stack set down at rest
             * jolted it at 0.5 s and again each time: a 10-box stack never slept) */
            timer[i] = nextafterf(d->sleep_time, 0.0f);
        }
    }
}

/* How many times a step may be solved (launched_past): the first, then once per link of a chain
 * of bodies set moving within the step (a Newton's cradle of 3 spheres takes 2). */
#define LAUNCH_ATTEMPTS 3

/* body_pairs' test (scale 1) for bodies a and b on the step's start poses, with margins ga, gb
 * (grow) and sa, sb (slack) */
static bool near_at_start(const solver* s, const ak_vec3* v0, uint32_t a, uint32_t b, float ga,
                          float gb, float sa, float sb, float offset, float dt) {
    float rb = s->bodies[a].bound_radius + s->bodies[b].bound_radius + offset;
    float rr = rb + (ga + gb);
    float d2 = ak_vec3_length_sq(ak_vec3_sub(s->x0[a], s->x0[b]));
    if (d2 > rr * rr) return false;
    if (s->awake[a] && s->awake[b]) {
        float rel = rb + (2.0f * dt * ak_vec3_distance(v0[a], v0[b]) + sa + sb);
        if (d2 > rel * rel) return false;
    }
    return true;
}

/* Whether the step has to be solved again: the broad phase, once per step, grows each body's
 * bounding sphere by its start speed v0 (plus launch) times dt, so a body at rest that an impact
 * or a joint sets moving within the step finds no pair with what lies ahead of it, and sinks into
 * it or passes through until the next step. A body went further than its margins covered when its
 * displacement in the step exceeds dt (|v0| + launch) by more than dt^2 |g| (what gravity adds)
 * plus a quarter of its bounding radius, or half the contact offset if more (bodies slowed or
 * stopped by a contact, a box landing, move less than that and never count; below a quarter of the
 * radius a body pushed within a pile sinks no deeper than that and is separated the next step, as
 * before: the 10,000 spheres poured by bench/vs_bullet were 24% slower when every push past half
 * the offset solved the step again); if margins grown by that excess (launch raised by excess /
 * dt, which adds twice the excess to the margins, as a start speed would) find a pair with a plane
 * or a body (through the step's sweep, sap[0 .. ns) along axis) that the step's margins did not,
 * its launch is raised and the step is solved again with it. A ragdoll's limb whipped faster than
 * it started by its joints, with nothing new in its reach, costs nothing more.
 */
static bool launched_past(const solver* s, const ak_vec3* v0, float* launch, const float* grow,
                          const float* slack, const sap_entry* sap, uint32_t ns, int axis, float dt,
                          float gmag, float offset, uint32_t n) {
    const ak_rigid_model* m = s->m;
    bool any = false;
    for (uint32_t i = 0; i < n; ++i) {
        if (!s->awake[i]) continue;
        float d = ak_vec3_distance(s->x[i], s->x0[i]);
        float excess = d - dt * (ak_vec3_length(v0[i]) + launch[i]);
        if (!(excess > dt * dt * gmag + ak_maxf(0.5f * offset, 0.25f * s->bodies[i].bound_radius)))
            continue;
        float gi = grow[i] + 2.0f * excess, si = slack[i] + 2.0f * excess;
        const rigid_body* bi = &s->bodies[i];
        bool found = false;
        for (size_t k = 0; k < m->plane_count && !found; ++k) {
            const rigid_body* pl = &s->bodies[m->planes[k]];
            float dist = ak_vec3_dot(ak_vec3_sub(s->x0[i], s->x0[m->planes[k]]), pl->shape.normal) -
                         bi->bound_radius;
            found = !(dist > offset + gi) && dist > offset + grow[i];
        }
        float c = axis_comp(s->x0[i], axis), reach = bi->bound_radius + offset + gi;
        for (uint32_t e = 0; e < ns && !found && sap[e].lo <= c + reach; ++e) {
            uint32_t j = sap[e].body;
            if (j == i || sap[e].hi < c - reach) continue;
            if (bi->group != 0 && bi->group == s->bodies[j].group) continue;
            if (m->joint_count && joined(m, i, j)) continue;
            found = near_at_start(s, v0, i, j, gi, grow[j], si, slack[j], offset, dt) &&
                    !near_at_start(s, v0, i, j, grow[i], grow[j], slack[i], slack[j], offset, dt);
        }
        if (found) {
            launch[i] += excess / dt;
            any = true;
        }
    }
    return any;
}

/* ---- persistent contact anchors (ak_rigid_contact_anchor) ------------------------------- */

/* The job's anchor of the pair of bodies lo < hi, or NULL (binary search: sorted by key). */
static const ak_rigid_contact_anchor* anchor_find(const ak_rigid_step_job* job, uint32_t lo,
                                                  uint32_t hi) {
    const ak_rigid_contact_anchor* e = job->contact_anchors.ptr;
    uint32_t l = 0, r = *job->contact_anchor_count;
    ak_rigid_contact_anchor key = {.body_a = lo, .body_b = hi};
    while (l < r) {
        uint32_t mid = l + (r - l) / 2;
        if (anchor_before(&e[mid], &key))
            l = mid + 1;
        else
            r = mid;
    }
    return l < *job->contact_anchor_count && e[l].body_a == lo && e[l].body_b == hi ? &e[l] : NULL;
}

/* Each cached pair's carry from the job's anchors, on the step's start poses: the drift turned
 * to world by body_b's start orientation and taken along the contact plane, oriented from
 * the pair's b to its a. A pair whose normal has turned by more than about 6 degrees from the
 * anchor's (another face or edge now touches) starts again from zero. */
static void anchors_read(solver* s, const ak_rigid_step_job* job, pair_buf* pb,
                         const contact_buf* cb) {
    for (uint32_t i = 0; i < pb->count; ++i) {
        pair_entry* e = &pb->p[i];
        e->carry = ak_vec3_zero();
        e->carry_twist = 0.0f;
        if (!job->contact_anchors.count || !e->cached || e->end == e->start) continue;
        uint32_t lo = e->a < e->b ? e->a : e->b, hi = e->a < e->b ? e->b : e->a;
        const ak_rigid_contact_anchor* an = anchor_find(job, lo, hi);
        if (!an) continue;
        float sign = e->a == lo ? 1.0f : -1.0f;
        ak_vec3 n = cb->c[e->start].n;
        ak_vec3 nw = ak_vec3_scale(ak_mat3_mul_vec3(s->rot0[hi], an->normal), sign);
        if (!(ak_vec3_dot(nw, n) > 0.995f)) continue;
        ak_vec3 d = ak_vec3_scale(ak_mat3_mul_vec3(s->rot0[hi], an->drift), sign);
        e->carry = ak_vec3_madd(d, n, -ak_vec3_dot(d, n));
        /* (the entry's twist is not carried: the drift, read at the centre of pressure, already
         * holds the twist's motion there, and static friction undoes it with the turn its arm
         * gives; torsional friction undoing the carried twist again overshot, and the pair
         * rocked about the normal from step to step: a 20-layer pyramid at rest spun at up to
         * 0.14 rad/s and drifted 17.5 mm in 5 s at 4 substeps, 1.2 mm without it) */
        e->carry_twist = 0.0f;
    }
}

/* Rotation vector of body i over the whole step (after it). */
static ak_vec3 step_turn_end(const solver* s, uint32_t i) {
    return s->awake[i] ? small_turn(s->q[i], s->q0[i]) : ak_vec3_zero();
}

/* Motion over the whole step of body i's local point l (as patch_slip and moved_point read it
 * during the solve: translation and the turn about n only on a patch). */
static ak_vec3 step_slip(const solver* s, uint32_t i, ak_vec3 l, ak_vec3 n, bool patch) {
    if (!s->awake[i]) return ak_vec3_zero();
    ak_vec3 r0 = ak_mat3_mul_vec3(s->rot0[i], l);
    if (patch) {
        float turn = ak_vec3_dot(step_turn_end(s, i), n);
        return ak_vec3_add(s->ds[i], ak_vec3_scale(ak_vec3_cross(n, r0), turn));
    }
    return ak_vec3_add(s->ds[i], ak_vec3_sub(ak_quat_rotate(s->q[i], l), r0));
}

/* The step's anchors into the job's cache: every cached pair whose static friction held in the
 * last substep keeps its carry plus the slip the step left at its centre of pressure (along
 * the contact plane, in body_b's frame); a pair that slid, separated or has no room starts
 * again. Sorted by key (shell sort: no allocation, keys unique so the order is total). */
static void anchors_write(const solver* s, const ak_rigid_step_job* job, const pair_buf* pb,
                          const contact_buf* cb) {
    ak_rigid_contact_anchor* out = job->contact_anchors.ptr;
    uint32_t cap = (uint32_t)(job->contact_anchors.count > UINT32_MAX ? UINT32_MAX
                                                                       : job->contact_anchors.count);
    uint32_t na = 0;
    for (uint32_t i = 0; i < pb->count && na < cap; ++i) {
        const pair_entry* e = &pb->p[i];
        if (!e->cached || e->end == e->start || !s->held[e->start]) continue;
        ak_vec3 la, lb;
        float lambda, arm;
        uint32_t points = 0;
        ak_vec3 n = cb->c[e->start].n;
        if (!pressure_centre(cb, e->start, e->end, &la, &lb, &lambda, &arm, &points)) continue;
        bool patch = points >= 2 && s->awake[e->a] && s->awake[e->b];
        ak_vec3 d = ak_vec3_add(e->carry, ak_vec3_sub(step_slip(s, e->a, la, n, patch),
                                                      step_slip(s, e->b, lb, n, patch)));
        d = ak_vec3_madd(d, n, -ak_vec3_dot(d, n));
        uint32_t lo = e->a < e->b ? e->a : e->b, hi = e->a < e->b ? e->b : e->a;
        float sign = e->a == lo ? 1.0f : -1.0f;
        float tw = e->carry_twist +
                   ak_vec3_dot(ak_vec3_sub(step_turn_end(s, e->a), step_turn_end(s, e->b)), n);
        ak_quat qi = ak_quat_conjugate(s->q[hi]);
        out[na++] = (ak_rigid_contact_anchor){
            .body_a = lo,
            .body_b = hi,
            .drift = ak_quat_rotate(qi, ak_vec3_scale(d, sign)),
            .normal = ak_quat_rotate(qi, ak_vec3_scale(n, sign)),
            .twist = tw,
        };
    }
    static const uint32_t gaps[] = {701, 301, 132, 57, 23, 10, 4, 1};
    for (size_t gi = 0; gi < sizeof gaps / sizeof gaps[0]; ++gi)
        for (uint32_t i = gaps[gi]; i < na; ++i) {
            ak_rigid_contact_anchor t = out[i];
            uint32_t j = i;
            for (; j >= gaps[gi] && anchor_before(&t, &out[j - gaps[gi]]); j -= gaps[gi])
                out[j] = out[j - gaps[gi]];
            out[j] = t;
        }
    *job->contact_anchor_count = na;
}

ak_result ak_rigid_step_run(const ak_rigid_step_job* job) { return akp_rigid_step_run(job, true); }

ak_result akp_rigid_step_run(const ak_rigid_step_job* job, bool islands) {
    ak_result r = ak_rigid_step_validate(job);
    if (r != AK_OK) return r;
    const ak_rigid_model* m = job->model;
    uint32_t n = (uint32_t)m->body_count;
    layout l = layout_of(m);
    unsigned char* base = (unsigned char*)(((uintptr_t)job->scratch.ptr + 15) & ~(uintptr_t)15);
    ak_vec3* x0 = (ak_vec3*)(base + l.x0);
    ak_quat* q0 = (ak_quat*)(base + l.q0);
    ak_vec3* v0 = (ak_vec3*)(base + l.v0);
    ak_vec3* w0 = (ak_vec3*)(base + l.w0);
    uint8_t* awake = base + l.awake;
    uint32_t substeps = job->substeps ? job->substeps : 10;
    solver s = {
        .m = m,
        .bodies = m->bodies,
        .x = job->positions.ptr,
        .q = job->orientations.ptr,
        .v = job->velocities.ptr,
        .w = job->angular_velocities.ptr,
        .x0 = x0,
        .qp = (ak_quat*)(base + l.qp),
        .dx = (ak_vec3*)(base + l.dx),
        .ds = (ak_vec3*)(base + l.ds),
        .q0 = q0,
        .awake = awake,
        .iw = (ak_mat3*)(base + l.iw),
        .drive_targets = job->drive_targets.count ? job->drive_targets.ptr : NULL,
        .rows = (contact_row*)(base + l.rows),
        .cx = (ak_vec3*)(base + l.cx),
        .ct = (ak_vec3*)(base + l.ct),
        .rot = (ak_mat3*)(base + l.rot),
        .rot0 = (ak_mat3*)(base + l.rot0),
        .held = base + l.held,
        .h = job->dt / (float)substeps,
        .push_max = INFINITY,
    };
    memcpy(x0, s.x, n * sizeof *x0);
    memcpy(q0, s.q, n * sizeof *q0);
    memcpy(v0, s.v, n * sizeof *v0);
    memcpy(w0, s.w, n * sizeof *w0);
    const bool sleeping = job->sleep_timers.count > 0;
    ak_vec3 up = ak_vec3_scale(ak_vec3_normalize(job->gravity), -1.0f);
    float gmag = ak_vec3_length(job->gravity);
    float offset = m->desc.contact_offset;
    float* launch = (float*)(base + l.launch);
    memset(launch, 0, n * sizeof *launch);
    contact_buf cb;
    pair_buf pb;
    uint32_t ns = 0;
    int axis = 0;
    /* the step, again from its start with wider margins for the bodies an impact or a joint
     * sent further than their pairs' margins covered (launched_past), at most LAUNCH_ATTEMPTS
     * times in all */
    for (int attempt = 1;; ++attempt) {
        memset(s.ds, 0, n * sizeof *s.ds);
        for (uint32_t i = 0; i < n; ++i) {
            awake[i] = m->bodies[i].inv_mass > 0.0f &&
                       !(sleeping && job->sleep_timers.ptr[i] >= m->desc.sleep_time);
            if (awake[i]) s.q[i] = q0[i] = ak_quat_normalize(s.q[i]);
            s.rot0[i] = ak_mat3_from_quat(q0[i]);
        }
        cb = (contact_buf){(rigid_contact*)(base + l.contacts), 0, m->desc.max_contacts, 0,
                           (contact_group*)(base + l.groups),   0};
        s.push_max = INFINITY;
        /* pairs once per step (Mueller et al. 2020: "collect potential pairs once per time step"),
         * with margins that cover the step's motion; flat pairs keep their contacts for every
         * substep, the others run the narrow phase in each */
        pb = (pair_buf){(pair_entry*)(base + l.pairs), 0, m->desc.max_contacts, 0};
        find_pairs(&s, (sap_entry*)(base + l.sap), &cb, &pb, (float*)(base + l.grow),
                   (float*)(base + l.slack), launch, offset, job->dt, gmag, up, &ns, &axis);
        uint32_t kept = cb.count;
        memset(s.held, 0, kept);
        anchors_read(&s, job, &pb, &cb);
        uint32_t nj = (uint32_t)m->joint_count, chains = 0;
        uint32_t* order = (uint32_t*)(base + l.jorder);
        uint32_t* start = (uint32_t*)(base + l.jstart);
        if (nj)
            chains = joint_chains(&s, (uint32_t*)(base + l.parent), (uint32_t*)(base + l.croot),
                                  (uint32_t*)(base + l.jchain), order, start);
        island* isl = (island*)(base + l.islands);
        uint32_t islands_n =
            islands
                ? build_islands(&s, &pb, kept, m->desc.max_contacts, chains, order, start,
                                (uint32_t*)(base + l.parent), (uint32_t*)(base + l.island_of),
                                (uint32_t*)(base + l.ibodies), (pair_entry*)(base + l.ipairs),
                                (uint32_t*)(base + l.ijoints), (uint32_t*)(base + l.ichains), isl)
                : 0;
        if (islands_n) {
            /* what no island writes (static bodies; the others are set again in each substep) */
            for (uint32_t i = 0; i < n; ++i) {
                s.cx[i] = s.ct[i] = ak_vec3_zero();
                s.rot[i] = ak_mat3_from_quat(s.q[i]);
            }
            /* the islands shared out over the threads in contiguous runs of about equal work */
            uint64_t total = 0;
            uint32_t busy = 0;
            for (uint32_t k = 0; k < islands_n; ++k) total += isl[k].work, busy += isl[k].work > 0;
            uint32_t want = job->thread_count ? job->thread_count : 1;
            if (want > busy) want = busy ? busy : 1;
            if (want > AKP_TASKS_MAX) want = AKP_TASKS_MAX;
            island_task itasks[AK_RIGID_MAX_THREADS];
            uint32_t itasks_n = 0, k = 0;
            uint64_t acc = 0;
            for (uint32_t t = 0; t < want; ++t) {
                uint32_t k0 = k;
                uint64_t upto = total * (t + 1) / want;
                while (k < islands_n && (t + 1 == want || acc + isl[k].work <= upto))
                    acc += isl[k++].work;
                if (k == k0 && k < islands_n) acc += isl[k++].work;
                if (k == k0) continue;
                itasks[itasks_n++] = (island_task){.s = &s,
                                                   .isl = isl,
                                                   .i0 = k0,
                                                   .i1 = k,
                                                   .ibodies = (uint32_t*)(base + l.ibodies),
                                                   .ijoints = (uint32_t*)(base + l.ijoints),
                                                   .ichains = (uint32_t*)(base + l.ichains),
                                                   .order = order,
                                                   .start = start,
                                                   .ipairs = (pair_entry*)(base + l.ipairs),
                                                   .c = cb.c,
                                                   .groups = cb.groups,
                                                   .gravity = job->gravity,
                                                   .offset = offset,
                                                   .gmag = gmag,
                                                   .substeps = substeps};
            }
            if (itasks_n > 1)
                akp_run_tasks(solve_islands, itasks, sizeof itasks[0], itasks_n);
            else if (itasks_n)
                solve_islands(&itasks[0]);
            /* the last substep's contacts brought together after the cached ones (regions ascend,
             * so each moves down over free room) */
            uint32_t cursor = kept;
            for (uint32_t i = 0; i < islands_n; ++i) {
                if (!isl[i].awake) continue;
                if (isl[i].count_last && cursor != isl[i].region)
                    memmove(cb.c + cursor, cb.c + isl[i].region, isl[i].count_last * sizeof *cb.c);
                cursor += isl[i].count_last;
                cb.dropped += isl[i].dropped;
            }
            cb.count = cursor;
        } else {
            /* joints, contacts, then up to eight more sweeps over the joints: contacts solved last
             * would pull a ragdoll's joints apart at an impact, and one sweep leaves a chain of
             * joints (pelvis, spine, chest) 6 degrees past a limit under load. The later sweeps go
             * chain by chain, the chains shared out over the threads in contiguous runs of about
             * equal joint counts: each chain's numbers are the same whichever thread sweeps it. */
            chain_task tasks[AK_RIGID_MAX_THREADS];
            uint32_t tasks_n = 1;
            tasks[0] = (chain_task){.s = &s, .c0 = 0, .c1 = 0, .sweeps = 8};
            if (nj) {
                uint32_t want = job->thread_count ? job->thread_count : 1;
                if (want > chains) want = chains;
                if (want > AKP_TASKS_MAX) want = AKP_TASKS_MAX;
                uint32_t c = 0;
                tasks_n = 0;
                for (uint32_t t = 0; t < want; ++t) {
                    uint32_t c0 = c;
                    /* chains up to the t+1-th share of the joints */
                    uint64_t upto = (uint64_t)nj * (t + 1) / want;
                    while (c < chains && (t + 1 == want || start[c + 1] <= upto)) ++c;
                    if (c == c0 && c < chains) ++c;
                    if (c == c0) continue;
                    tasks[tasks_n++] = (chain_task){
                        .s = &s, .order = order, .start = start, .c0 = c0, .c1 = c, .sweeps = 8};
                }
            }
            for (uint32_t step = 0; step < substeps; ++step) {
                predict(&s, job->gravity, m->desc.linear_damping, m->desc.angular_damping, NULL, n);
                substep_contacts(&s, &cb, pb.p, pb.count, kept, offset);
                /* joints, contacts, then eight more sweeps over the joints: contacts solved last
                 * would pull a ragdoll's joints apart at an impact, and one sweep leaves a chain of
                 * joints (pelvis, spine, chest) 6 degrees past a limit under load; joints are few
                 * and cheap */
                if (nj) {
                    float err = 0.0f;
                    solve_joints(&s, NULL, nj, &err);
                }
                solve_positions(&s, &cb, NULL, n);
                /* (the sweeps stop early, chain by chain, once one corrects no joint of the chain
                 * by more than joint_tolerance, by default 1e-4, 0.1 mm or 0.1 mrad: 50 falling
                 * ragdolls take 4.3 sweeps a substep instead of 9 when they all stop together, and
                 * their anchors stay within 0.02 mm) */
                if (tasks_n > 1)
                    akp_run_tasks(sweep_chains, tasks, sizeof tasks[0], tasks_n);
                else if (nj)
                    sweep_chains(&tasks[0]);
                if (m->desc.contacts_after_joints) contacts_after_joints(&s, &cb);
                update_velocities(&s, NULL, n);
                damp_drives(&s, NULL, nj);
                solve_velocities(&s, &cb, gmag);
            }
        }
        if (attempt >= LAUNCH_ATTEMPTS || pb.dropped ||
            !launched_past(&s, v0, launch, (const float*)(base + l.grow),
                           (const float*)(base + l.slack), (const sap_entry*)(base + l.sap), ns,
                           axis, job->dt, gmag, offset, n))
            break;
        memcpy(s.x, x0, n * sizeof *x0);
        memcpy(s.q, q0, n * sizeof *q0);
        memcpy(s.v, v0, n * sizeof *v0);
        memcpy(s.w, w0, n * sizeof *w0);
    }
    bool finite = true;
    for (uint32_t i = 0; i < n && finite; ++i)
        finite = ak_vec3_is_finite(s.x[i]) && ak_quat_is_finite(s.q[i]) &&
                 ak_vec3_is_finite(s.v[i]) && ak_vec3_is_finite(s.w[i]);
    if (!finite) {
        memcpy(s.x, x0, n * sizeof *x0);
        memcpy(s.q, q0, n * sizeof *q0);
        memcpy(s.v, v0, n * sizeof *v0);
        memcpy(s.w, w0, n * sizeof *w0);
        return AK_ERR_BAD_DATA;
    }
    if (job->out_max_penetration) {
        float worst = 0.0f;
        for (uint32_t k = 0; k < cb.count; ++k) {
            const rigid_contact* c = &cb.c[k];
            float d = ak_vec3_dot(
                ak_vec3_sub(world_point(&s, c->b, c->lb), world_point(&s, c->a, c->la)), c->n);
            worst = ak_maxf(worst, d);
        }
        *job->out_max_penetration = worst;
    }
    if (job->out_contact_count) *job->out_contact_count = cb.count;
    if (job->out_dropped_contacts) *job->out_dropped_contacts = cb.dropped;
    if (job->contact_anchors.count) anchors_write(&s, job, &pb, &cb);
    if (sleeping) update_sleep(&s, job, &cb, (uint32_t*)(base + l.parent));
    return AK_OK;
}
