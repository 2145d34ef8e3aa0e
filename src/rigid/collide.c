/* Narrow phase: contact points between pairs of spheres, boxes, capsules, hulls and planes.
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

/* ---- hulls: GJK, SAT when the cores overlap, face clipping ---------------------------------
 *
 * A convex shape is a core (a hull's or a box's polytope, a capsule's segment, a sphere's centre)
 * swept by a radius. GJK finds the cores' closest points when they are apart (the exact
 * distance and normal, all that a speculative contact within the offset needs); when the cores
 * overlap a separating axis test over the faces of both and the edge pairs that make a face of
 * the Minkowski difference (Gauss-map pruning) gives the axis of least penetration, exact for
 * polytopes. Face contacts then clip the incident feature (face, segment or point) against the
 * reference face's sides for a manifold of several points, as box_box does. */

enum { CV_POINT, CV_SEGMENT, CV_POLY };

typedef struct cvx {
    int kind;
    float radius;
    float hh; /* segment: half length along local Y */
    ak_vec3 x;
    ak_quat q, qi;
    const akp_hull* h;
} cvx;

/* A box as a hull (its faces counter-clockwise seen from outside). */
typedef struct box_hull {
    akp_hull h;
    ak_vec3 v[8];
    akp_hull_face f[6];
    uint32_t idx[24];
    akp_hull_edge e[12];
} box_hull;

static void box_hull_make(box_hull* b, ak_vec3 he) {
    static const uint32_t quads[6][4] = {{1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3},
                                         {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}};
    static const float normals[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                        {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    memset(b, 0, sizeof *b);
    for (int i = 0; i < 8; ++i)
        b->v[i] = ak_vec3_make(i & 1 ? he.x : -he.x, i & 2 ? he.y : -he.y, i & 4 ? he.z : -he.z);
    for (int f = 0; f < 6; ++f) {
        b->f[f].n = ak_vec3_make(normals[f][0], normals[f][1], normals[f][2]);
        b->f[f].d = comp(he, f / 2);
        b->f[f].first = (uint32_t)(4 * f);
        b->f[f].count = 4;
        for (int k = 0; k < 4; ++k) b->idx[4 * f + k] = quads[f][k];
    }
    int ne = 0;
    for (int f = 0; f < 6; ++f)
        for (int k = 0; k < 4; ++k) {
            uint32_t a = quads[f][k], c = quads[f][(k + 1) % 4];
            if (a > c) continue;
            for (int g = 0; g < 6; ++g)
                for (int m = 0; m < 4; ++m)
                    if (quads[g][m] == c && quads[g][(m + 1) % 4] == a)
                        b->e[ne++] = (akp_hull_edge){a, c, (uint32_t)f, (uint32_t)g};
        }
    b->h.verts = b->v;
    b->h.faces = b->f;
    b->h.idx = b->idx;
    b->h.edges = b->e;
    b->h.nv = 8;
    b->h.nf = 6;
    b->h.ne = (uint32_t)ne;
    b->h.bound_radius = ak_vec3_length(he);
}

static void cvx_make(cvx* c, const ak_rigid_shape* s, const akp_hull* h, rigid_pose p,
                     box_hull* box) {
    memset(c, 0, sizeof *c);
    c->x = p.x;
    c->q = p.q;
    c->qi = ak_quat_conjugate(p.q);
    switch (s->type) {
    case AK_RIGID_SPHERE:
        c->kind = CV_POINT;
        c->radius = s->radius;
        break;
    case AK_RIGID_CAPSULE:
        c->kind = s->half_height > 1e-6f ? CV_SEGMENT : CV_POINT;
        c->radius = s->radius;
        c->hh = s->half_height;
        break;
    case AK_RIGID_BOX:
        box_hull_make(box, s->half_extents);
        c->kind = CV_POLY;
        c->h = &box->h;
        break;
    default:
        c->kind = CV_POLY;
        c->h = h;
        break;
    }
}

static ak_vec3 cvx_world(const cvx* c, ak_vec3 l) { return ak_vec3_add(c->x, ak_quat_rotate(c->q, l)); }

static ak_vec3 cvx_support(const cvx* c, ak_vec3 d) {
    ak_vec3 dl = ak_quat_rotate(c->qi, d), l = ak_vec3_zero();
    if (c->kind == CV_SEGMENT) {
        l.y = dl.y >= 0.0f ? c->hh : -c->hh;
    } else if (c->kind == CV_POLY) {
        float best = -INFINITY;
        for (uint32_t i = 0; i < c->h->nv; ++i) {
            float s = ak_vec3_dot(c->h->verts[i], dl);
            if (s > best) best = s, l = c->h->verts[i];
        }
    }
    return cvx_world(c, l);
}

typedef struct gjk_v {
    ak_vec3 w, a, b; /* w = a - b */
} gjk_v;

/* Closest point to the origin of the simplex s[0..*n): keeps only the vertices that support it
 * (in s, *n updated) with their weights in lam; false when the origin is inside a tetrahedron. */
static bool simplex_closest(gjk_v* s, int* n, float* lam) {
    if (*n == 1) {
        lam[0] = 1.0f;
        return true;
    }
    if (*n == 2) {
        ak_vec3 a = s[0].w, ab = ak_vec3_sub(s[1].w, a);
        float l2 = ak_vec3_dot(ab, ab), t = l2 > 0.0f ? -ak_vec3_dot(a, ab) / l2 : 0.0f;
        if (t <= 0.0f) {
            *n = 1, lam[0] = 1.0f;
        } else if (t >= 1.0f) {
            s[0] = s[1], *n = 1, lam[0] = 1.0f;
        } else {
            lam[0] = 1.0f - t, lam[1] = t;
        }
        return true;
    }
    if (*n == 3) {
        /* Ericson, Real-Time Collision Detection 5.1.5, with p the origin */
        ak_vec3 a = s[0].w, b = s[1].w, c = s[2].w;
        ak_vec3 ab = ak_vec3_sub(b, a), ac = ak_vec3_sub(c, a), ap = ak_vec3_neg(a);
        float d1 = ak_vec3_dot(ab, ap), d2 = ak_vec3_dot(ac, ap);
        if (d1 <= 0.0f && d2 <= 0.0f) {
            *n = 1, lam[0] = 1.0f;
            return true;
        }
        ak_vec3 bp = ak_vec3_neg(b);
        float d3 = ak_vec3_dot(ab, bp), d4 = ak_vec3_dot(ac, bp);
        if (d3 >= 0.0f && d4 <= d3) {
            s[0] = s[1], *n = 1, lam[0] = 1.0f;
            return true;
        }
        float vc = d1 * d4 - d3 * d2;
        if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
            float v = d1 / (d1 - d3);
            *n = 2, lam[0] = 1.0f - v, lam[1] = v;
            return true;
        }
        ak_vec3 cp = ak_vec3_neg(c);
        float d5 = ak_vec3_dot(ab, cp), d6 = ak_vec3_dot(ac, cp);
        if (d6 >= 0.0f && d5 <= d6) {
            s[0] = s[2], *n = 1, lam[0] = 1.0f;
            return true;
        }
        float vb = d5 * d2 - d1 * d6;
        if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
            float w = d2 / (d2 - d6);
            s[1] = s[2], *n = 2, lam[0] = 1.0f - w, lam[1] = w;
            return true;
        }
        float va = d3 * d6 - d5 * d4;
        if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
            float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            s[0] = s[1], s[1] = s[2], *n = 2, lam[0] = 1.0f - w, lam[1] = w;
            return true;
        }
        float den = va + vb + vc;
        if (!(den > 0.0f)) { /* degenerate triangle: its best edge */
            *n = 2;
            return simplex_closest(s, n, lam);
        }
        float v = vb / den, w = vc / den;
        lam[0] = 1.0f - v - w, lam[1] = v, lam[2] = w;
        return true;
    }
    /* tetrahedron: the closest point is on a face the origin lies outside of */
    static const int faces[4][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
    float best = INFINITY;
    gjk_v bs[3];
    int bn = 0;
    float bl[3] = {0, 0, 0};
    bool outside_any = false;
    for (int f = 0; f < 4; ++f) {
        ak_vec3 a = s[faces[f][0]].w, b = s[faces[f][1]].w, c = s[faces[f][2]].w,
                d = s[faces[f][3]].w;
        ak_vec3 nrm = ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(c, a));
        float so = -ak_vec3_dot(a, nrm), sd = ak_vec3_dot(ak_vec3_sub(d, a), nrm);
        if (!(so * sd < 0.0f) && sd != 0.0f) continue;
        outside_any = true;
        gjk_v t[3] = {s[faces[f][0]], s[faces[f][1]], s[faces[f][2]]};
        int tn = 3;
        float tl[3];
        simplex_closest(t, &tn, tl);
        ak_vec3 v = ak_vec3_zero();
        for (int k = 0; k < tn; ++k) v = ak_vec3_madd(v, t[k].w, tl[k]);
        float l2 = ak_vec3_dot(v, v);
        if (l2 < best) {
            best = l2, bn = tn;
            for (int k = 0; k < tn; ++k) bs[k] = t[k], bl[k] = tl[k];
        }
    }
    if (!outside_any) return false;
    *n = bn;
    for (int k = 0; k < bn; ++k) s[k] = bs[k], lam[k] = bl[k];
    return true;
}

/* GJK on the cores; false when they overlap (or touch within 1e-6 m). */
static bool gjk_cores(const cvx* A, const cvx* B, ak_vec3* out_pa, ak_vec3* out_pb) {
    gjk_v s[4];
    int n = 1;
    float lam[4] = {1, 0, 0, 0};
    ak_vec3 d = ak_vec3_sub(A->x, B->x);
    if (ak_vec3_length_sq(d) < 1e-12f) d = ak_vec3_make(1.0f, 0.0f, 0.0f);
    s[0].a = cvx_support(A, ak_vec3_neg(d));
    s[0].b = cvx_support(B, d);
    s[0].w = ak_vec3_sub(s[0].a, s[0].b);
    ak_vec3 v = s[0].w;
    for (int it = 0; it < 64; ++it) {
        if (!simplex_closest(s, &n, lam)) return false;
        v = ak_vec3_zero();
        for (int k = 0; k < n; ++k) v = ak_vec3_madd(v, s[k].w, lam[k]);
        float vv = ak_vec3_dot(v, v);
        if (vv < 1e-12f) return false;
        gjk_v w;
        w.a = cvx_support(A, ak_vec3_neg(v));
        w.b = cvx_support(B, v);
        w.w = ak_vec3_sub(w.a, w.b);
        if (vv - ak_vec3_dot(v, w.w) <= 1e-6f * vv) break;
        bool dup = false;
        for (int k = 0; k < n; ++k) dup = dup || ak_vec3_distance(s[k].w, w.w) < 1e-7f;
        if (dup || n == 4) break;
        s[n++] = w;
    }
    ak_vec3 pa = ak_vec3_zero(), pb = ak_vec3_zero();
    for (int k = 0; k < n; ++k) pa = ak_vec3_madd(pa, s[k].a, lam[k]), pb = ak_vec3_madd(pb, s[k].b, lam[k]);
    *out_pa = pa;
    *out_pb = pb;
    return ak_vec3_distance(pa, pb) > 1e-6f;
}

bool akp_rigid_gjk(const ak_rigid_shape* sa, const akp_hull* ha, rigid_pose pa,
                   const ak_rigid_shape* sb, const akp_hull* hb, rigid_pose pb, ak_vec3* out_pa,
                   ak_vec3* out_pb) {
    cvx A, B;
    box_hull ba, bb;
    cvx_make(&A, sa, ha, pa, &ba);
    cvx_make(&B, sb, hb, pb, &bb);
    return gjk_cores(&A, &B, out_pa, out_pb);
}

typedef struct cand {
    ak_vec3 p1, p2; /* on the first shape's surface, on the second's */
    float s;
} cand;

#define MAX_CAND 64

/* Up to AKP_RIGID_MAX_PAIR_CONTACTS of the candidates (p1 on A when a_first): the deepest, then
 * each next the one farthest from those kept, so the manifold spans the contact patch. */
static void emit(hits* hs, cand* c, int count, ak_vec3 n, bool a_first) {
    int room = AKP_RIGID_MAX_PAIR_CONTACTS - hs->count;
    if (count <= room) {
        for (int i = 0; i < count; ++i) {
            if (a_first)
                add_hit(hs, c[i].p1, c[i].p2, n);
            else
                add_hit(hs, c[i].p2, c[i].p1, n);
        }
        return;
    }
    bool kept[MAX_CAND] = {false};
    int nk = 0;
    int first = -1;
    for (int i = 0; i < count; ++i)
        if (first < 0 || c[i].s < c[first].s) first = i;
    for (int i = first; i >= 0 && nk < room;) {
        kept[i] = true;
        ++nk;
        if (a_first)
            add_hit(hs, c[i].p1, c[i].p2, n);
        else
            add_hit(hs, c[i].p2, c[i].p1, n);
        int next = -1;
        float far = -1.0f;
        for (int j = 0; j < count; ++j) {
            if (kept[j]) continue;
            float dmin = INFINITY;
            for (int k = 0; k < count; ++k)
                if (kept[k]) dmin = ak_minf(dmin, ak_vec3_distance(c[j].p1, c[k].p1));
            if (dmin > far) far = dmin, next = j;
        }
        i = next;
    }
}

/* Hull (A) on a plane (B). */
static void hull_plane(hits* hs, const cvx* A, ak_vec3 p0, ak_vec3 n) {
    cand c[MAX_CAND];
    int count = 0;
    for (uint32_t i = 0; i < A->h->nv; ++i) {
        /* the vertices on the plane's side; the shallowest are dropped past MAX_CAND */
        ak_vec3 w = cvx_world(A, A->h->verts[i]);
        float s = ak_vec3_dot(ak_vec3_sub(w, p0), n);
        if (!(s < hs->margin)) continue;
        if (count < MAX_CAND) {
            c[count++] = (cand){w, ak_vec3_madd(w, n, -s), s};
        } else {
            int worst = 0;
            for (int k = 1; k < count; ++k)
                if (c[k].s > c[worst].s) worst = k;
            if (s < c[worst].s) c[worst] = (cand){w, ak_vec3_madd(w, n, -s), s};
        }
    }
    emit(hs, c, count, n, true);
}

/* The polygon of face f of a polytope, in the world, into out (at most cap points). */
static int face_poly(const cvx* c, uint32_t f, ak_vec3* out, int cap) {
    const akp_hull_face* face = &c->h->faces[f];
    int k = 0;
    for (uint32_t i = 0; i < face->count && k < cap; ++i)
        out[k++] = cvx_world(c, c->h->verts[c->h->idx[face->first + i]]);
    return k;
}

/* Face of a polytope whose world normal is most along d; *out_align gets the cosine. */
static uint32_t best_face(const cvx* c, ak_vec3 d, float* out_align) {
    ak_vec3 dl = ak_quat_rotate(c->qi, d);
    uint32_t best = 0;
    float align = -INFINITY;
    for (uint32_t f = 0; f < c->h->nf; ++f) {
        float a = ak_vec3_dot(c->h->faces[f].n, dl);
        if (a > align) align = a, best = f;
    }
    *out_align = align;
    return best;
}

#define CLIP_CAP 256

/* Contacts of reference face rf of polytope R against the incident shape I (its feature that
 * faces R): the incident feature clipped against the face's sides, each point kept while it is
 * within margin of the face. R is A when ref_is_a. False when nothing was left to report. */
static bool clip_face(hits* hs, const cvx* R, uint32_t rf, const cvx* I, bool ref_is_a) {
    ak_vec3 nr = ak_quat_rotate(R->q, R->h->faces[rf].n);
    ak_vec3 ref[CLIP_CAP], poly[CLIP_CAP], tmp[CLIP_CAP];
    int nref = face_poly(R, rf, ref, CLIP_CAP);
    int count = 0;
    if (I->kind == CV_POINT) {
        poly[count++] = I->x;
    } else if (I->kind == CV_SEGMENT) {
        ak_vec3 ax = ak_vec3_scale(ak_quat_rotate(I->q, ak_vec3_make(0.0f, 1.0f, 0.0f)), I->hh);
        poly[count++] = ak_vec3_sub(I->x, ax);
        poly[count++] = ak_vec3_add(I->x, ax);
    } else {
        float al;
        uint32_t inf = best_face(I, ak_vec3_neg(nr), &al);
        count = face_poly(I, inf, poly, CLIP_CAP / 2);
    }
    ak_vec3 rc = ref[0];
    for (int e = 0; e < nref && count > 0; ++e) {
        ak_vec3 a = ref[e], b = ref[(e + 1) % nref];
        ak_vec3 u = ak_vec3_cross(ak_vec3_sub(b, a), nr);
        float ul = ak_vec3_length(u);
        if (ul < 1e-9f) continue;
        u = ak_vec3_scale(u, 1.0f / ul);
        float off = ak_vec3_dot(u, a);
        if (count == 1) {
            if (ak_vec3_dot(poly[0], u) > off) count = 0;
        } else if (count == 2 && I->kind == CV_SEGMENT) {
            float da = ak_vec3_dot(poly[0], u) - off, db = ak_vec3_dot(poly[1], u) - off;
            if (da > 0.0f && db > 0.0f) {
                count = 0;
            } else if (da > 0.0f) {
                poly[0] = ak_vec3_lerp(poly[0], poly[1], da / (da - db));
            } else if (db > 0.0f) {
                poly[1] = ak_vec3_lerp(poly[0], poly[1], da / (da - db));
            }
        } else if (2 * count <= CLIP_CAP) { /* clip_poly emits at most 2 per edge */
            count = clip_poly(poly, count, u, off, tmp);
        }
    }
    if (count == 0) return false;
    cand c[MAX_CAND];
    int nc = 0;
    for (int i = 0; i < count; ++i) {
        float s = ak_vec3_dot(ak_vec3_sub(poly[i], rc), nr) - I->radius;
        if (!(s < hs->margin)) continue;
        ak_vec3 on_i = ak_vec3_madd(poly[i], nr, -I->radius);
        ak_vec3 on_r = ak_vec3_madd(on_i, nr, -s);
        if (nc < MAX_CAND) c[nc++] = (cand){on_r, on_i, s};
    }
    if (nc == 0) return true; /* apart along the face normal: nothing to report */
    emit(hs, c, nc, ref_is_a ? ak_vec3_neg(nr) : nr, ref_is_a);
    return true;
}

/* Separation of the polytope P from the core X along world axis l (P towards X): min over X
 * minus max over P, radii not included. */
static float axis_sep(const cvx* P, const cvx* X, ak_vec3 l) {
    ak_vec3 sp = cvx_support(P, l), sx = cvx_support(X, ak_vec3_neg(l));
    return ak_vec3_dot(ak_vec3_sub(sx, sp), l);
}

/* Overlapping cores, P a polytope, X any core: SAT. */
static void sat_pair(hits* hs, const cvx* X, const cvx* P, bool x_is_a) {
    /* P's faces: the separation along a face's normal is the other's lowest point above the
     * face's plane, d_f known */
    float best = -INFINITY;
    uint32_t bf = 0;
    for (uint32_t f = 0; f < P->h->nf; ++f) {
        ak_vec3 n = ak_quat_rotate(P->q, P->h->faces[f].n);
        ak_vec3 sx = cvx_support(X, ak_vec3_neg(n));
        float s = ak_vec3_dot(ak_vec3_sub(sx, P->x), n) - P->h->faces[f].d;
        if (s > best) best = s, bf = f;
    }
    int kind = 0; /* 0: P's face; 1: X's face; 2: edges */
    float best_x = -INFINITY;
    uint32_t bxf = 0;
    if (X->kind == CV_POLY)
        for (uint32_t f = 0; f < X->h->nf; ++f) {
            ak_vec3 n = ak_quat_rotate(X->q, X->h->faces[f].n);
            ak_vec3 sp = cvx_support(P, ak_vec3_neg(n));
            float s = ak_vec3_dot(ak_vec3_sub(sp, X->x), n) - X->h->faces[f].d;
            if (s > best_x) best_x = s, bxf = f;
        }
    if (best_x > best + 1e-3f) kind = 1;
    float best_face = kind == 1 ? best_x : best;
    /* edge pairs, in P's frame: X's edges (or segment) and face normals brought over once */
    float best_e = -INFINITY;
    ak_vec3 e_axis = ak_vec3_zero(), ep0 = ak_vec3_zero(), ep1 = ak_vec3_zero(),
            ex0 = ak_vec3_zero(), ex1 = ak_vec3_zero();
    if (X->kind != CV_POINT) {
        ak_quat xp = ak_quat_mul(P->qi, X->q); /* X's frame to P's */
        ak_vec3 xo = ak_quat_rotate(P->qi, ak_vec3_sub(X->x, P->x));
        uint32_t nxe = X->kind == CV_POLY ? X->h->ne : 1;
        for (uint32_t j = 0; j < nxe; ++j) {
            ak_vec3 xs0, xs1, c = ak_vec3_zero(), d = ak_vec3_zero();
            if (X->kind == CV_POLY) {
                const akp_hull_edge* e = &X->h->edges[j];
                xs0 = ak_vec3_add(xo, ak_quat_rotate(xp, X->h->verts[e->v0]));
                xs1 = ak_vec3_add(xo, ak_quat_rotate(xp, X->h->verts[e->v1]));
                c = ak_vec3_neg(ak_quat_rotate(xp, X->h->faces[e->f0].n));
                d = ak_vec3_neg(ak_quat_rotate(xp, X->h->faces[e->f1].n));
            } else {
                ak_vec3 ax = ak_vec3_scale(ak_quat_rotate(xp, ak_vec3_make(0, 1, 0)), X->hh);
                xs0 = ak_vec3_sub(xo, ax);
                xs1 = ak_vec3_add(xo, ax);
            }
            ak_vec3 dx = ak_vec3_sub(xs1, xs0), dxc = ak_vec3_cross(d, c);
            float dxl = ak_vec3_length(dx);
            for (uint32_t i = 0; i < P->h->ne; ++i) {
                const akp_hull_edge* e = &P->h->edges[i];
                if (X->kind == CV_POLY) {
                    /* Gregorius: the arcs a-b and c-d (X's normals negated) cross on the Gauss
                     * map, so the edges make a face of the Minkowski difference */
                    ak_vec3 a = P->h->faces[e->f0].n, b = P->h->faces[e->f1].n;
                    ak_vec3 bxa = ak_vec3_cross(b, a);
                    float cba = ak_vec3_dot(c, bxa), dba = ak_vec3_dot(d, bxa);
                    if (!(cba * dba < 0.0f)) continue;
                    float adc = ak_vec3_dot(a, dxc), bdc = ak_vec3_dot(b, dxc);
                    if (!(adc * bdc < 0.0f && cba * bdc > 0.0f)) continue;
                }
                ak_vec3 p0 = P->h->verts[e->v0], p1 = P->h->verts[e->v1];
                ak_vec3 pe = ak_vec3_sub(p1, p0);
                ak_vec3 l = ak_vec3_cross(pe, dx);
                float ll = ak_vec3_length(l);
                if (ll < 1e-5f * ak_vec3_length(pe) * dxl) continue;
                l = ak_vec3_scale(l, 1.0f / ll);
                if (ak_vec3_dot(l, p0) < 0.0f) l = ak_vec3_neg(l); /* P's centre is its origin */
                float sep;
                if (X->kind == CV_POLY) {
                    sep = ak_vec3_dot(l, ak_vec3_sub(xs0, p0));
                } else {
                    ak_vec3 lw = ak_quat_rotate(P->q, l);
                    sep = axis_sep(P, X, lw);
                }
                if (sep > best_e) {
                    best_e = sep, e_axis = l, ep0 = p0, ep1 = p1, ex0 = xs0, ex1 = xs1;
                }
            }
        }
        /* back to the world */
        e_axis = ak_quat_rotate(P->q, e_axis);
        ep0 = cvx_world(P, ep0), ep1 = cvx_world(P, ep1);
        ex0 = cvx_world(P, ex0), ex1 = cvx_world(P, ex1);
    }
    if (best_e > best_face + 0.02f * fabsf(best_face) + 1e-3f) {
        ak_vec3 c1, c2;
        segment_segment(ep0, ep1, ex0, ex1, &c1, &c2);
        /* e_axis points from P towards X */
        ak_vec3 on_x = ak_vec3_madd(c2, e_axis, -X->radius);
        if (x_is_a)
            add_hit(hs, on_x, c1, e_axis);
        else
            add_hit(hs, c1, on_x, ak_vec3_neg(e_axis));
        return;
    }
    if (kind == 1) {
        clip_face(hs, X, bxf, P, x_is_a);
        return;
    }
    if (!clip_face(hs, P, bf, X, !x_is_a)) {
        /* nothing within the face's sides (rounding at a corner): X's deepest point */
        ak_vec3 n = ak_quat_rotate(P->q, P->h->faces[bf].n);
        ak_vec3 deep = cvx_support(X, ak_vec3_neg(n));
        float s = axis_sep(P, X, n) - X->radius;
        ak_vec3 on_x = ak_vec3_madd(deep, n, -X->radius);
        ak_vec3 on_p = ak_vec3_madd(on_x, n, -s);
        if (x_is_a)
            add_hit(hs, on_x, on_p, n);
        else
            add_hit(hs, on_p, on_x, ak_vec3_neg(n));
    }
}

/* Any convex pair with at least one polytope; B must be a polytope (the dispatcher orders). */
static void convex_cvx(hits* hs, const cvx* pA, const cvx* pB) {
    const cvx A = *pA, B = *pB;
    ak_vec3 ca, cb;
    if (!gjk_cores(&A, &B, &ca, &cb)) {
        sat_pair(hs, &A, &B, true);
        return;
    }
    ak_vec3 d = ak_vec3_sub(ca, cb);
    float dist = ak_vec3_length(d);
    ak_vec3 n = ak_vec3_scale(d, 1.0f / dist); /* from B to A */
    float sep = dist - A.radius - B.radius;
    if (!(sep < hs->margin)) return;
    /* a face of either polytope along the normal becomes the reference */
    float al_a = -INFINITY, al_b = -INFINITY;
    uint32_t fa = 0, fb = best_face(&B, n, &al_b);
    if (A.kind == CV_POLY) fa = best_face(&A, ak_vec3_neg(n), &al_a);
    const float face_cos = 0.9995f;
    bool done = false;
    if (al_b >= face_cos && al_b >= al_a)
        done = clip_face(hs, &B, fb, &A, false);
    else if (al_a >= face_cos)
        done = clip_face(hs, &A, fa, &B, true);
    if (!done) add_hit(hs, ak_vec3_madd(ca, n, -A.radius), ak_vec3_madd(cb, n, B.radius), n);
}

static void convex_pair(hits* hs, rigid_pose pa, const ak_rigid_shape* sa, const akp_hull* ha,
                        rigid_pose pb, const ak_rigid_shape* sb, const akp_hull* hb) {
    cvx A, B;
    box_hull boxa, boxb;
    cvx_make(&A, sa, ha, pa, &boxa);
    cvx_make(&B, sb, hb, pb, &boxb);
    convex_cvx(hs, &A, &B);
}

/* ---- static heightfields and triangle meshes --------------------------------------------
 * Each triangle near the body is a thin polytope (its front and back faces, three edges) run
 * through the convex pair above; contacts whose normal points into the surface's back are
 * dropped (one-sided), the rest of all triangles gathered and reduced to a manifold. */

typedef struct tri_hull {
    akp_hull h;
    ak_vec3 v[3];
    akp_hull_face f[2];
    uint32_t idx[6];
    akp_hull_edge e[3];
} tri_hull;

#define MESH_HITS 64

typedef struct mesh_query {
    const cvx* A;
    rigid_pose pose; /* the mesh's */
    float margin;
    hit h[MESH_HITS];
    int count;
} mesh_query;

static void mesh_triangle(mesh_query* mq, ak_vec3 a, ak_vec3 b, ak_vec3 c) {
    ak_vec3 n = ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(c, a));
    float l = ak_vec3_length(n);
    if (!(l > 1e-12f)) return;
    n = ak_vec3_scale(n, 1.0f / l);
    tri_hull t;
    memset(&t, 0, sizeof t);
    t.v[0] = a, t.v[1] = b, t.v[2] = c;
    t.f[0] = (akp_hull_face){n, ak_vec3_dot(n, a), 0, 3};
    t.f[1] = (akp_hull_face){ak_vec3_neg(n), -ak_vec3_dot(n, a), 3, 3};
    t.idx[0] = 0, t.idx[1] = 1, t.idx[2] = 2, t.idx[3] = 0, t.idx[4] = 2, t.idx[5] = 1;
    t.e[0] = (akp_hull_edge){0, 1, 0, 1};
    t.e[1] = (akp_hull_edge){1, 2, 0, 1};
    t.e[2] = (akp_hull_edge){2, 0, 0, 1};
    t.h.verts = t.v, t.h.faces = t.f, t.h.idx = t.idx, t.h.edges = t.e;
    t.h.nv = 3, t.h.nf = 2, t.h.ne = 3;
    cvx B;
    memset(&B, 0, sizeof B);
    B.kind = CV_POLY;
    B.h = &t.h;
    B.x = mq->pose.x;
    B.q = mq->pose.q;
    B.qi = ak_quat_conjugate(mq->pose.q);
    hits one;
    one.count = 0;
    one.margin = mq->margin;
    convex_cvx(&one, mq->A, &B);
    ak_vec3 nw = ak_quat_rotate(mq->pose.q, n);
    for (int i = 0; i < one.count && mq->count < MESH_HITS; ++i)
        if (ak_vec3_dot(one.h[i].n, nw) > 0.0f) mq->h[mq->count++] = one.h[i];
}

/* Up to AKP_RIGID_MAX_PAIR_CONTACTS of h[0, count) into hs: the deepest point, then each next
 * the farthest from those kept. */
static void reduce_into(hits* hs, const hit* h, int count) {
    bool kept[MESH_HITS] = {false};
    int next = -1;
    float deepest = INFINITY;
    for (int i = 0; i < count; ++i) {
        float s = ak_vec3_dot(ak_vec3_sub(h[i].pa, h[i].pb), h[i].n);
        if (s < deepest) deepest = s, next = i;
    }
    while (next >= 0 && hs->count < AKP_RIGID_MAX_PAIR_CONTACTS) {
        kept[next] = true;
        add_hit(hs, h[next].pa, h[next].pb, h[next].n);
        next = -1;
        float far = -1.0f;
        for (int j = 0; j < count; ++j) {
            if (kept[j]) continue;
            float dmin = INFINITY;
            for (int k = 0; k < count; ++k)
                if (kept[k]) dmin = ak_minf(dmin, ak_vec3_distance(h[j].pa, h[k].pa));
            if (dmin > far) far = dmin, next = j;
        }
    }
}

static ak_vec3 mesh_vertex_hf(const akp_mesh* me, uint32_t i, uint32_t j) {
    return ak_vec3_make((float)i * me->spacing, me->heights[(size_t)j * me->cols + i],
                        (float)j * me->spacing);
}

static void mesh_pair(hits* hs, const cvx* A, float bound, rigid_pose pb, const akp_mesh* me) {
    mesh_query mq;
    mq.A = A;
    mq.pose = pb;
    mq.margin = hs->margin;
    mq.count = 0;
    ak_vec3 c = ak_quat_rotate(ak_quat_conjugate(pb.q), ak_vec3_sub(A->x, pb.x));
    float r = bound + hs->margin;
    if (me->is_heightfield) {
        if (c.y - r > me->max_height || c.y + r < me->min_height) return;
        float inv = 1.0f / me->spacing;
        float fi0 = floorf((c.x - r) * inv), fi1 = floorf((c.x + r) * inv);
        float fj0 = floorf((c.z - r) * inv), fj1 = floorf((c.z + r) * inv);
        float imax = (float)(me->cols - 2), jmax = (float)(me->rows - 2);
        if (fi1 < 0.0f || fj1 < 0.0f || fi0 > imax || fj0 > jmax) return;
        uint32_t i0 = (uint32_t)ak_maxf(fi0, 0.0f), i1 = (uint32_t)ak_minf(fi1, imax);
        uint32_t j0 = (uint32_t)ak_maxf(fj0, 0.0f), j1 = (uint32_t)ak_minf(fj1, jmax);
        for (uint32_t j = j0; j <= j1; ++j)
            for (uint32_t i = i0; i <= i1; ++i) {
                ak_vec3 p00 = mesh_vertex_hf(me, i, j), p10 = mesh_vertex_hf(me, i + 1, j),
                        p01 = mesh_vertex_hf(me, i, j + 1), p11 = mesh_vertex_hf(me, i + 1, j + 1);
                float lo = ak_minf(ak_minf(p00.y, p10.y), ak_minf(p01.y, p11.y));
                float hi = ak_maxf(ak_maxf(p00.y, p10.y), ak_maxf(p01.y, p11.y));
                if (lo > c.y + r || hi < c.y - r) continue;
                mesh_triangle(&mq, p00, p01, p11);
                mesh_triangle(&mq, p00, p11, p10);
            }
    } else {
        ak_vec3 lo = ak_vec3_sub(c, ak_vec3_make(r, r, r)), hi = ak_vec3_add(c, ak_vec3_make(r, r, r));
        uint32_t stack[64];
        int sp = 0;
        stack[sp++] = 0;
        while (sp > 0) {
            const akp_bvh_node* nd = &me->nodes[stack[--sp]];
            if (nd->lo.x > hi.x || nd->lo.y > hi.y || nd->lo.z > hi.z || nd->hi.x < lo.x ||
                nd->hi.y < lo.y || nd->hi.z < lo.z)
                continue;
            if (nd->count == 0) {
                if (sp + 2 <= 64) {
                    stack[sp++] = nd->first + 1;
                    stack[sp++] = nd->first;
                }
                continue;
            }
            for (uint32_t k = nd->first; k < nd->first + nd->count; ++k) {
                const uint32_t* t = &me->tris[3 * (size_t)me->order[k]];
                mesh_triangle(&mq, me->verts[t[0]], me->verts[t[1]], me->verts[t[2]]);
            }
        }
    }
    reduce_into(hs, mq.h, mq.count);
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
    case AK_RIGID_HULL:
        return 3;
    case AK_RIGID_HEIGHTFIELD:
    case AK_RIGID_TRIMESH:
        return 4;
    case AK_RIGID_PLANE:
        return 5;
    default:
        return 6;
    }
}

static void collide_any(hits* hs, rigid_pose pa, const rigid_body* ba, rigid_pose pb,
                        const rigid_body* bb) {
    const ak_rigid_shape* sa = &ba->shape;
    const ak_rigid_shape* sb = &bb->shape;
    const akp_hull* ha = ba->hull;
    const akp_hull* hb = bb->hull;
    if (bb->mesh) {
        if (ba->mesh || sa->type == AK_RIGID_PLANE) return;
        cvx A;
        box_hull boxa;
        cvx_make(&A, sa, ha, pa, &boxa);
        mesh_pair(hs, &A, ba->bound_radius, pb, bb->mesh);
    } else if (sa->type == AK_RIGID_HULL && sb->type == AK_RIGID_PLANE) {
        cvx A;
        cvx_make(&A, sa, ha, pa, NULL);
        hull_plane(hs, &A, pb.x, sb->normal);
    } else if (sb->type == AK_RIGID_HULL) {
        convex_pair(hs, pa, sa, ha, pb, sb, hb);
    } else if (sa->type == AK_RIGID_CAPSULE && sb->type == AK_RIGID_BOX)
        capsule_box(hs, pa, sa, pb, sb);
    else
        collide_ordered(hs, pa, sa, pb, sb);
}

/* Hits of ba at pa against bb at pb (bodies or a compound's children), n from b to a. */
static void pair_hits(hits* out, rigid_pose pa, const rigid_body* ba, rigid_pose pb,
                      const rigid_body* bb) {
    hits hs;
    hs.count = 0;
    hs.margin = out->margin;
    bool swap = rank_of(ba->shape.type) > rank_of(bb->shape.type);
    if (swap)
        collide_any(&hs, pb, bb, pa, ba);
    else
        collide_any(&hs, pa, ba, pb, bb);
    for (int i = 0; i < hs.count && out->count < AKP_RIGID_MAX_PAIR_CONTACTS; ++i) {
        hit h = hs.h[i];
        if (swap) {
            ak_vec3 t = h.pa;
            h.pa = h.pb;
            h.pb = t;
            h.n = ak_vec3_neg(h.n);
        }
        out->h[out->count++] = h;
    }
}

static rigid_pose pose_mul(rigid_pose a, rigid_pose b) {
    rigid_pose r = {ak_vec3_add(a.x, ak_quat_rotate(a.q, b.x)), ak_quat_mul(a.q, b.q)};
    return r;
}

/* A compound against anything: every pair of children (a body that is not a compound is its
 * own single child), the points gathered and reduced to one manifold. */
static void compound_hits(hits* hs, rigid_pose pa, const rigid_body* ba, rigid_pose pb,
                          const rigid_body* bb) {
    hit big[MESH_HITS];
    int nb = 0;
    uint32_t na = ba->compound ? ba->compound->count : 1, nbk = bb->compound ? bb->compound->count : 1;
    for (uint32_t i = 0; i < na; ++i) {
        const rigid_body* ka = ba->compound ? &ba->compound->kids[i] : ba;
        rigid_pose wa = ba->compound ? pose_mul(pa, ba->compound->poses[i]) : pa;
        for (uint32_t j = 0; j < nbk; ++j) {
            const rigid_body* kb = bb->compound ? &bb->compound->kids[j] : bb;
            rigid_pose wb = bb->compound ? pose_mul(pb, bb->compound->poses[j]) : pb;
            float rr = ka->bound_radius + kb->bound_radius + hs->margin;
            if (isfinite(rr) && ak_vec3_length_sq(ak_vec3_sub(wa.x, wb.x)) > rr * rr) continue;
            hits one;
            one.count = 0;
            one.margin = hs->margin;
            pair_hits(&one, wa, ka, wb, kb);
            for (int k = 0; k < one.count && nb < MESH_HITS; ++k) big[nb++] = one.h[k];
        }
    }
    reduce_into(hs, big, nb);
}

int akp_rigid_collide(const ak_rigid_model* m, uint32_t a, uint32_t b, rigid_pose pa, rigid_pose pb,
                      float margin, rigid_contact* out, int cap) {
    const rigid_body* ba = &m->bodies[a];
    const rigid_body* bb = &m->bodies[b];
    hits hs;
    hs.count = 0;
    hs.margin = margin;
    if (ba->compound || bb->compound)
        compound_hits(&hs, pa, ba, pb, bb);
    else
        pair_hits(&hs, pa, ba, pb, bb);
    int count = hs.count < cap ? hs.count : cap;
    ak_quat qa = ak_quat_conjugate(pa.q), qb = ak_quat_conjugate(pb.q);
    for (int i = 0; i < count; ++i) {
        hit h = hs.h[i];
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
