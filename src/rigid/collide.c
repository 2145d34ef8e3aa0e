/* Narrow phase: contact points between pairs of spheres, boxes, capsules and planes.
 *
 * Every routine works in a canonical order (the "lower" shape first) and reports world points
 * pa on the first shape, pb on the second and the normal n from the second to the first; the
 * dispatcher swaps back. Separation s = (pa - pb) . n (negative when overlapping). */
#include <math.h>
#include <string.h>

#include "rigid_impl.h"

typedef struct hit {
    ak_vec3 pa, pb, n;
} hit;

typedef struct hits {
    hit h[AKP_RIGID_MAX_PAIR_CONTACTS];
    int count;
    float margin;
} hits;

static void add_hit(hits* hs, ak_vec3 pa, ak_vec3 pb, ak_vec3 n) {
    float s = ak_vec3_dot(ak_vec3_sub(pa, pb), n);
    if (!(s < hs->margin) || hs->count >= AKP_RIGID_MAX_PAIR_CONTACTS) return;
    hs->h[hs->count].pa = pa;
    hs->h[hs->count].pb = pb;
    hs->h[hs->count].n = n;
    hs->count++;
}

static ak_vec3 axis_of(ak_quat q, int k) {
    ak_vec3 e = ak_vec3_zero();
    if (k == 0)
        e.x = 1.0f;
    else if (k == 1)
        e.y = 1.0f;
    else
        e.z = 1.0f;
    return ak_quat_rotate(q, e);
}

static float comp(ak_vec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

static ak_vec3 closest_on_segment(ak_vec3 p, ak_vec3 a, ak_vec3 b) {
    ak_vec3 ab = ak_vec3_sub(b, a);
    float l2 = ak_vec3_dot(ab, ab);
    float t = l2 > 0.0f ? ak_clampf(ak_vec3_dot(ak_vec3_sub(p, a), ab) / l2, 0.0f, 1.0f) : 0.0f;
    return ak_vec3_madd(a, ab, t);
}

/* Closest points c1 on segment p1-q1 and c2 on p2-q2 (minimising |c1 - c2|). */
static void segment_segment(ak_vec3 p1, ak_vec3 q1, ak_vec3 p2, ak_vec3 q2, ak_vec3* c1,
                            ak_vec3* c2) {
    ak_vec3 d1 = ak_vec3_sub(q1, p1), d2 = ak_vec3_sub(q2, p2), r = ak_vec3_sub(p1, p2);
    float a = ak_vec3_dot(d1, d1), e = ak_vec3_dot(d2, d2), f = ak_vec3_dot(d2, r);
    float s, t;
    if (a <= 1e-12f && e <= 1e-12f) {
        s = t = 0.0f;
    } else if (a <= 1e-12f) {
        s = 0.0f;
        t = ak_clampf(f / e, 0.0f, 1.0f);
    } else {
        float c = ak_vec3_dot(d1, r);
        if (e <= 1e-12f) {
            t = 0.0f;
            s = ak_clampf(-c / a, 0.0f, 1.0f);
        } else {
            float b = ak_vec3_dot(d1, d2), den = a * e - b * b;
            s = den > 1e-12f * a * e ? ak_clampf((b * f - c * e) / den, 0.0f, 1.0f) : 0.0f;
            t = (b * s + f) / e;
            if (t < 0.0f) {
                t = 0.0f;
                s = ak_clampf(-c / a, 0.0f, 1.0f);
            } else if (t > 1.0f) {
                t = 1.0f;
                s = ak_clampf((b - c) / a, 0.0f, 1.0f);
            }
        }
    }
    *c1 = ak_vec3_madd(p1, d1, s);
    *c2 = ak_vec3_madd(p2, d2, t);
}

/* Two spheres (centres ca, cb, radii ra, rb). */
static void sphere_sphere(hits* hs, ak_vec3 ca, float ra, ak_vec3 cb, float rb) {
    ak_vec3 d = ak_vec3_sub(ca, cb);
    float l = ak_vec3_length(d);
    ak_vec3 n = l > 1e-9f ? ak_vec3_scale(d, 1.0f / l) : ak_vec3_make(0.0f, 1.0f, 0.0f);
    add_hit(hs, ak_vec3_madd(ca, n, -ra), ak_vec3_madd(cb, n, rb), n);
}

static void sphere_plane(hits* hs, ak_vec3 c, float r, ak_vec3 p0, ak_vec3 n) {
    ak_vec3 pa = ak_vec3_madd(c, n, -r);
    float s = ak_vec3_dot(ak_vec3_sub(pa, p0), n);
    add_hit(hs, pa, ak_vec3_madd(pa, n, -s), n);
}

/* Sphere (centre c, radius r) against box (centre xb, orientation qb, half extents he). */
static void sphere_box(hits* hs, ak_vec3 c, float r, ak_vec3 xb, ak_quat qb, ak_vec3 he) {
    ak_vec3 lc = ak_quat_rotate(ak_quat_conjugate(qb), ak_vec3_sub(c, xb));
    ak_vec3 cl = ak_vec3_make(ak_clampf(lc.x, -he.x, he.x), ak_clampf(lc.y, -he.y, he.y),
                              ak_clampf(lc.z, -he.z, he.z));
    ak_vec3 nl;
    ak_vec3 d = ak_vec3_sub(lc, cl);
    float l = ak_vec3_length(d);
    if (l > 1e-7f) {
        nl = ak_vec3_scale(d, 1.0f / l);
    } else {
        /* centre inside: leave through the nearest face */
        float best = INFINITY;
        int k = 1;
        for (int i = 0; i < 3; ++i) {
            float gap = comp(he, i) - fabsf(comp(lc, i));
            if (gap < best) best = gap, k = i;
        }
        float sgn = comp(lc, k) >= 0.0f ? 1.0f : -1.0f;
        nl = ak_vec3_zero();
        if (k == 0)
            nl.x = sgn, cl.x = sgn * he.x;
        else if (k == 1)
            nl.y = sgn, cl.y = sgn * he.y;
        else
            nl.z = sgn, cl.z = sgn * he.z;
    }
    ak_vec3 n = ak_quat_rotate(qb, nl);
    ak_vec3 pb = ak_vec3_add(xb, ak_quat_rotate(qb, cl));
    add_hit(hs, ak_vec3_madd(c, n, -r), pb, n);
}

static void capsule_ends(rigid_pose p, const ak_rigid_shape* s, ak_vec3* e0, ak_vec3* e1) {
    ak_vec3 ax = ak_vec3_scale(axis_of(p.q, 1), s->half_height);
    *e0 = ak_vec3_sub(p.x, ax);
    *e1 = ak_vec3_add(p.x, ax);
}

static void capsule_capsule(hits* hs, rigid_pose pa, const ak_rigid_shape* sa, rigid_pose pb,
                            const ak_rigid_shape* sb) {
    ak_vec3 a0, a1, b0, b1, c1, c2;
    capsule_ends(pa, sa, &a0, &a1);
    capsule_ends(pb, sb, &b0, &b1);
    ak_vec3 da = ak_vec3_sub(a1, a0), db = ak_vec3_sub(b1, b0);
    float la = ak_vec3_length(da), lb = ak_vec3_length(db);
    if (la > 1e-6f && lb > 1e-6f && fabsf(ak_vec3_dot(da, db)) > 0.995f * la * lb) {
        /* (nearly) parallel: a line of contact; its ends are where each segment's ends project */
        const ak_vec3 ends[4] = {a0, a1, b0, b1};
        for (int i = 0; i < 4; ++i) {
            ak_vec3 on_a = i < 2 ? ends[i] : closest_on_segment(ends[i], a0, a1);
            ak_vec3 on_b = i < 2 ? closest_on_segment(ends[i], b0, b1) : ends[i];
            sphere_sphere(hs, on_a, sa->radius, on_b, sb->radius);
        }
        return;
    }
    segment_segment(a0, a1, b0, b1, &c1, &c2);
    sphere_sphere(hs, c1, sa->radius, c2, sb->radius);
}

static void capsule_box(hits* hs, rigid_pose pa, const ak_rigid_shape* sa, rigid_pose pb,
                        const ak_rigid_shape* sb) {
    ak_vec3 a0, a1;
    capsule_ends(pa, sa, &a0, &a1);
    sphere_box(hs, a0, sa->radius, pb.x, pb.q, sb->half_extents);
    sphere_box(hs, a1, sa->radius, pb.x, pb.q, sb->half_extents);
    /* the segment's point nearest the box: alternate projections (converges for convex sets) */
    ak_quat qi = ak_quat_conjugate(pb.q);
    ak_vec3 l0 = ak_quat_rotate(qi, ak_vec3_sub(a0, pb.x)),
            l1 = ak_quat_rotate(qi, ak_vec3_sub(a1, pb.x));
    ak_vec3 he = sb->half_extents, p = ak_vec3_scale(ak_vec3_add(l0, l1), 0.5f);
    for (int it = 0; it < 8; ++it) {
        ak_vec3 cb = ak_vec3_make(ak_clampf(p.x, -he.x, he.x), ak_clampf(p.y, -he.y, he.y),
                                  ak_clampf(p.z, -he.z, he.z));
        p = closest_on_segment(cb, l0, l1);
    }
    float ll = ak_vec3_distance(l0, l1);
    if (ak_vec3_distance(p, l0) > 0.05f * ll && ak_vec3_distance(p, l1) > 0.05f * ll)
        sphere_box(hs, ak_vec3_add(pb.x, ak_quat_rotate(pb.q, p)), sa->radius, pb.x, pb.q, he);
}

static void box_plane(hits* hs, rigid_pose pa, ak_vec3 he, ak_vec3 p0, ak_vec3 n) {
    for (int i = 0; i < 8; ++i) {
        ak_vec3 c = ak_vec3_make(i & 1 ? he.x : -he.x, i & 2 ? he.y : -he.y, i & 4 ? he.z : -he.z);
        ak_vec3 w = ak_vec3_add(pa.x, ak_quat_rotate(pa.q, c));
        float s = ak_vec3_dot(ak_vec3_sub(w, p0), n);
        if (s < hs->margin) add_hit(hs, w, ak_vec3_madd(w, n, -s), n);
    }
}

/* Clip a polygon (count points, in place, capacity 8... 16) to the half-space (p . u) <= e. */
static int clip_poly(ak_vec3* poly, int count, ak_vec3 u, float e, ak_vec3* tmp) {
    int out = 0;
    for (int i = 0; i < count; ++i) {
        ak_vec3 p = poly[i], q = poly[(i + 1) % count];
        float dp = ak_vec3_dot(p, u) - e, dq = ak_vec3_dot(q, u) - e;
        if (dp <= 0.0f) tmp[out++] = p;
        if ((dp < 0.0f && dq > 0.0f) || (dp > 0.0f && dq < 0.0f))
            tmp[out++] = ak_vec3_lerp(p, q, dp / (dp - dq));
    }
    memcpy(poly, tmp, (size_t)out * sizeof *poly);
    return out;
}

/* Box against box by the separating axis test; face contacts clip the incident face against the
 * reference face's sides. */
static void box_box(hits* hs, rigid_pose pa, ak_vec3 ha, rigid_pose pb, ak_vec3 hb) {
    ak_vec3 ua[3], ub[3];
    for (int k = 0; k < 3; ++k) ua[k] = axis_of(pa.q, k), ub[k] = axis_of(pb.q, k);
    ak_vec3 d = ak_vec3_sub(pb.x, pa.x);
    float c[3][3], ac[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            c[i][j] = ak_vec3_dot(ua[i], ub[j]), ac[i][j] = fabsf(c[i][j]) + 1e-6f;
    float best_face = -INFINITY;
    int face_kind = 0, face_k = 0; /* kind 0: a face of A is the reference; 1: of B */
    for (int i = 0; i < 3; ++i) {
        float ra = comp(ha, i), rb = hb.x * ac[i][0] + hb.y * ac[i][1] + hb.z * ac[i][2];
        float s = fabsf(ak_vec3_dot(d, ua[i])) - ra - rb;
        if (s > hs->margin) return;
        if (s > best_face + 1e-4f) best_face = s, face_kind = 0, face_k = i;
    }
    for (int j = 0; j < 3; ++j) {
        float ra = ha.x * ac[0][j] + ha.y * ac[1][j] + ha.z * ac[2][j], rb = comp(hb, j);
        float s = fabsf(ak_vec3_dot(d, ub[j])) - ra - rb;
        if (s > hs->margin) return;
        /* prefer A's faces unless B's are clearly better, so a resting pair keeps its manifold */
        if (s > best_face + 1e-3f) best_face = s, face_kind = 1, face_k = j;
    }
    float best_edge = -INFINITY;
    int ei = -1, ej = -1;
    ak_vec3 edge_axis = ak_vec3_zero();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            ak_vec3 l = ak_vec3_cross(ua[i], ub[j]);
            float len = ak_vec3_length(l);
            if (len < 1e-4f) continue;
            l = ak_vec3_scale(l, 1.0f / len);
            float ra = 0.0f, rb = 0.0f;
            for (int k = 0; k < 3; ++k)
                ra += comp(ha, k) * fabsf(ak_vec3_dot(ua[k], l)),
                    rb += comp(hb, k) * fabsf(ak_vec3_dot(ub[k], l));
            float s = fabsf(ak_vec3_dot(d, l)) - ra - rb;
            if (s > hs->margin) return;
            if (s > best_edge) best_edge = s, ei = i, ej = j, edge_axis = l;
        }
    if (ei >= 0 && best_edge > best_face + 0.02f * fabsf(best_face) + 1e-3f) {
        ak_vec3 l = edge_axis;
        if (ak_vec3_dot(l, d) < 0.0f) l = ak_vec3_neg(l); /* from A towards B */
        ak_vec3 ca = pa.x, cb = pb.x;
        for (int k = 0; k < 3; ++k) {
            if (k != ei)
                ca = ak_vec3_madd(ca, ua[k],
                                  ak_vec3_dot(l, ua[k]) >= 0.0f ? comp(ha, k) : -comp(ha, k));
            if (k != ej)
                cb = ak_vec3_madd(cb, ub[k],
                                  ak_vec3_dot(l, ub[k]) >= 0.0f ? -comp(hb, k) : comp(hb, k));
        }
        ak_vec3 ea = ak_vec3_scale(ua[ei], comp(ha, ei)), eb = ak_vec3_scale(ub[ej], comp(hb, ej));
        ak_vec3 c1, c2;
        segment_segment(ak_vec3_sub(ca, ea), ak_vec3_add(ca, ea), ak_vec3_sub(cb, eb),
                        ak_vec3_add(cb, eb), &c1, &c2);
        add_hit(hs, c1, c2, ak_vec3_neg(l));
        return;
    }
    /* reference box R, incident box I */
    const ak_vec3* ur = face_kind == 0 ? ua : ub;
    const ak_vec3* ui = face_kind == 0 ? ub : ua;
    ak_vec3 hr = face_kind == 0 ? ha : hb, hi = face_kind == 0 ? hb : ha;
    ak_vec3 xr = face_kind == 0 ? pa.x : pb.x, xi = face_kind == 0 ? pb.x : pa.x;
    ak_vec3 nref = ur[face_k];
    if (ak_vec3_dot(nref, ak_vec3_sub(xi, xr)) < 0.0f) nref = ak_vec3_neg(nref);
    /* incident face: the one of I most opposed to nref */
    int ik = 0;
    float most = -1.0f;
    for (int k = 0; k < 3; ++k) {
        float a = fabsf(ak_vec3_dot(ui[k], nref));
        if (a > most) most = a, ik = k;
    }
    float sgn = ak_vec3_dot(ui[ik], nref) > 0.0f ? -1.0f : 1.0f;
    ak_vec3 fc = ak_vec3_madd(xi, ui[ik], sgn * comp(hi, ik));
    int k1 = (ik + 1) % 3, k2 = (ik + 2) % 3;
    ak_vec3 e1 = ak_vec3_scale(ui[k1], comp(hi, k1)), e2 = ak_vec3_scale(ui[k2], comp(hi, k2));
    ak_vec3 poly[16], tmp[16];
    poly[0] = ak_vec3_add(ak_vec3_add(fc, e1), e2);
    poly[1] = ak_vec3_add(ak_vec3_sub(fc, e1), e2);
    poly[2] = ak_vec3_sub(ak_vec3_sub(fc, e1), e2);
    poly[3] = ak_vec3_sub(ak_vec3_add(fc, e1), e2);
    int count = 4;
    ak_vec3 rc = ak_vec3_madd(xr, nref, comp(hr, face_k)); /* reference face centre */
    for (int s = 1; s <= 2 && count > 0; ++s) {
        int k = (face_k + s) % 3;
        ak_vec3 u = ur[k];
        float off = ak_vec3_dot(rc, u);
        count = clip_poly(poly, count, u, off + comp(hr, k), tmp);
        if (count > 0) count = clip_poly(poly, count, ak_vec3_neg(u), -off + comp(hr, k), tmp);
    }
    /* faces that line up put incident corners on the clip planes, where rounding adds a second
     * point a hair away: one of each such cluster is kept, or the manifold's uneven points tilt
     * a resting box */
    float tol = 1e-4f * (1.0f + comp(hr, (face_k + 1) % 3) + comp(hr, (face_k + 2) % 3));
    for (int i = 0; i < count; ++i) {
        bool dup = false;
        for (int k = 0; k < i && !dup; ++k) dup = ak_vec3_distance(poly[i], poly[k]) < tol;
        if (dup) continue;
        float s = ak_vec3_dot(ak_vec3_sub(poly[i], rc), nref);
        ak_vec3 on_ref = ak_vec3_madd(poly[i], nref, -s);
        if (face_kind == 1)
            add_hit(hs, poly[i], on_ref, nref); /* B is the reference */
        else
            add_hit(hs, on_ref, poly[i], ak_vec3_neg(nref));
    }
}

/* Shapes in canonical order: type(a) <= type(b) with the enum's order sphere, box, capsule,
 * plane, except that the routines above take (sphere, box) as sphere first, etc. */
static void collide_ordered(hits* hs, rigid_pose pa, const ak_rigid_shape* sa, rigid_pose pb,
                            const ak_rigid_shape* sb) {
    ak_rigid_shape_type ta = sa->type, tb = sb->type;
    if (ta == AK_RIGID_SPHERE) {
        if (tb == AK_RIGID_SPHERE)
            sphere_sphere(hs, pa.x, sa->radius, pb.x, sb->radius);
        else if (tb == AK_RIGID_BOX)
            sphere_box(hs, pa.x, sa->radius, pb.x, pb.q, sb->half_extents);
        else if (tb == AK_RIGID_CAPSULE) {
            ak_vec3 b0, b1;
            capsule_ends(pb, sb, &b0, &b1);
            sphere_sphere(hs, pa.x, sa->radius, closest_on_segment(pa.x, b0, b1), sb->radius);
        } else
            sphere_plane(hs, pa.x, sa->radius, pb.x, sb->normal);
    } else if (ta == AK_RIGID_BOX) {
        if (tb == AK_RIGID_BOX)
            box_box(hs, pa, sa->half_extents, pb, sb->half_extents);
        else if (tb == AK_RIGID_PLANE)
            box_plane(hs, pa, sa->half_extents, pb.x, sb->normal);
    } else if (ta == AK_RIGID_CAPSULE) {
        if (tb == AK_RIGID_CAPSULE)
            capsule_capsule(hs, pa, sa, pb, sb);
        else if (tb == AK_RIGID_PLANE) {
            ak_vec3 a0, a1;
            capsule_ends(pa, sa, &a0, &a1);
            sphere_plane(hs, a0, sa->radius, pb.x, sb->normal);
            sphere_plane(hs, a1, sa->radius, pb.x, sb->normal);
        }
    }
}

/* Rank that decides which shape goes first (box before capsule: capsule_box takes the capsule
 * first, so capsule-box pairs are flipped below). */
static int rank_of(ak_rigid_shape_type t) {
    switch (t) {
    case AK_RIGID_SPHERE:
        return 0;
    case AK_RIGID_CAPSULE:
        return 1;
    case AK_RIGID_BOX:
        return 2;
    default:
        return 3;
    }
}

static void collide_any(hits* hs, rigid_pose pa, const ak_rigid_shape* sa, rigid_pose pb,
                        const ak_rigid_shape* sb) {
    if (sa->type == AK_RIGID_CAPSULE && sb->type == AK_RIGID_BOX)
        capsule_box(hs, pa, sa, pb, sb);
    else
        collide_ordered(hs, pa, sa, pb, sb);
}

int akp_rigid_collide(const ak_rigid_model* m, uint32_t a, uint32_t b, rigid_pose pa, rigid_pose pb,
                      float margin, rigid_contact* out, int cap) {
    const ak_rigid_shape* sa = &m->bodies[a].shape;
    const ak_rigid_shape* sb = &m->bodies[b].shape;
    hits hs;
    hs.count = 0;
    hs.margin = margin;
    bool swap = rank_of(sa->type) > rank_of(sb->type);
    if (swap)
        collide_any(&hs, pb, sb, pa, sa);
    else
        collide_any(&hs, pa, sa, pb, sb);
    int count = hs.count < cap ? hs.count : cap;
    ak_quat qa = ak_quat_conjugate(pa.q), qb = ak_quat_conjugate(pb.q);
    for (int i = 0; i < count; ++i) {
        hit h = hs.h[i];
        if (swap) {
            ak_vec3 t = h.pa;
            h.pa = h.pb;
            h.pb = t;
            h.n = ak_vec3_neg(h.n);
        }
        rigid_contact* c = &out[i];
        memset(c, 0, sizeof *c);
        c->a = a;
        c->b = b;
        c->n = h.n;
        c->la = ak_quat_rotate(qa, ak_vec3_sub(h.pa, pa.x));
        c->lb = ak_quat_rotate(qb, ak_vec3_sub(h.pb, pb.x));
        c->depth = ak_vec3_dot(ak_vec3_sub(h.pb, h.pa), h.n);
    }
    return hs.count;
}
