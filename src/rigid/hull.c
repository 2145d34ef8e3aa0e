/* Convex hulls of point sets for the rigid module: an incremental hull in double precision,
 * coplanar triangles merged into polygon faces, the solid's exact mass properties (tetrahedra
 * from an interior point) and its principal frame.
 *
 * The incremental hull: start from the four points that span the most volume, add the others
 * one by one (each sees the triangles it lies above by more than a tolerance; their boundary,
 * the horizon, is joined to the point). Afterwards every input point must lie under every face
 * within the tolerance and the triangle mesh must be closed (Euler: T = 2V - 4): points too
 * nearly degenerate for that are refused, not patched. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rigid_impl.h"

typedef struct dv3 {
    double x, y, z;
} dv3;

static dv3 dv(double x, double y, double z) {
    dv3 r = {x, y, z};
    return r;
}
static dv3 dsub(dv3 a, dv3 b) { return dv(a.x - b.x, a.y - b.y, a.z - b.z); }
static dv3 dadd(dv3 a, dv3 b) { return dv(a.x + b.x, a.y + b.y, a.z + b.z); }
static dv3 dscale(dv3 a, double s) { return dv(a.x * s, a.y * s, a.z * s); }
static double ddot(dv3 a, dv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv3 dcross(dv3 a, dv3 b) {
    return dv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static double dlen(dv3 a) { return sqrt(ddot(a, a)); }

typedef struct htri {
    uint32_t v[3];
    dv3 n;
    double d;
    uint32_t group;
} htri;

typedef struct hedge {
    uint32_t lo, hi, tri;
} hedge;

static size_t align16(size_t s) { return (s + 15) & ~(size_t)15; }

/* Most triangles a hull of n points has (2n - 4) plus room for one insertion. */
static size_t max_tris(size_t n) { return 2 * n + 8; }

size_t akp_rigid_hull_size(size_t n) {
    return align16(sizeof(akp_hull)) + align16(n * sizeof(ak_vec3)) +
           align16(max_tris(n) * sizeof(akp_hull_face)) +
           align16(3 * max_tris(n) * sizeof(uint32_t)) +
           align16(3 * max_tris(n) / 2 * sizeof(akp_hull_edge) + sizeof(akp_hull_edge));
}

size_t akp_rigid_hull_scratch_size(size_t n) {
    size_t t = max_tris(n);
    return align16(n * sizeof(dv3)) + align16(t * sizeof(htri)) + align16(t * sizeof(uint32_t)) +
           align16(3 * t * 2 * sizeof(uint32_t)) + align16(3 * t * sizeof(hedge)) +
           align16(t * sizeof(uint32_t)) + align16(n * sizeof(uint32_t)) +
           align16(t * sizeof(dv3)) + 64;
}

static bool tri_set(htri* t, const dv3* p, uint32_t a, uint32_t b, uint32_t c) {
    dv3 n = dcross(dsub(p[b], p[a]), dsub(p[c], p[a]));
    double l = dlen(n);
    if (!(l > 0.0)) return false;
    t->v[0] = a, t->v[1] = b, t->v[2] = c;
    t->n = dscale(n, 1.0 / l);
    t->d = ddot(t->n, p[a]);
    return true;
}

static int hedge_cmp(const void* x, const void* y) {
    const hedge* a = x;
    const hedge* b = y;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->tri < b->tri ? -1 : (a->tri > b->tri);
}

static uint32_t uf_find(uint32_t* parent, uint32_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Eigen decomposition of a symmetric 3x3 (cyclic Jacobi): a becomes diagonal, v's columns the
 * eigenvectors (v[row][col]). */
static void jacobi3(double a[3][3], double v[3][3]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) v[i][j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 50; ++sweep) {
        double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        double scale = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        if (off <= 1e-15 * scale) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (fabs(a[p][q]) <= 1e-300) continue;
                double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) {
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
}

void akp_rigid_principal(double inert[3][3], ak_quat* out_frame, ak_vec3* out_moments) {
    double vec[3][3];
    double offd = fabs(inert[0][1]) + fabs(inert[0][2]) + fabs(inert[1][2]);
    double diag = fabs(inert[0][0]) + fabs(inert[1][1]) + fabs(inert[2][2]);
    if (offd <= 1e-6 * diag) {
        /* already principal (up to rounding): keep the given axes */
        for (int r = 0; r < 3; ++r)
            for (int q = 0; q < 3; ++q) {
                vec[r][q] = r == q ? 1.0 : 0.0;
                if (r != q) inert[r][q] = 0.0;
            }
    } else {
        jacobi3(inert, vec);
        double det = vec[0][0] * (vec[1][1] * vec[2][2] - vec[2][1] * vec[1][2]) -
                     vec[0][1] * (vec[1][0] * vec[2][2] - vec[2][0] * vec[1][2]) +
                     vec[0][2] * (vec[1][0] * vec[2][1] - vec[2][0] * vec[1][1]);
        if (det < 0.0)
            for (int r = 0; r < 3; ++r) vec[r][2] = -vec[r][2];
    }
    ak_mat3 rm = ak_mat3_from_cols(
        ak_vec3_make((float)vec[0][0], (float)vec[1][0], (float)vec[2][0]),
        ak_vec3_make((float)vec[0][1], (float)vec[1][1], (float)vec[2][1]),
        ak_vec3_make((float)vec[0][2], (float)vec[1][2], (float)vec[2][2]));
    *out_frame = ak_quat_normalize(ak_quat_from_mat3(rm));
    *out_moments = ak_vec3_make((float)inert[0][0], (float)inert[1][1], (float)inert[2][2]);
}

#define FAIL(code, msg)                                                                            \
    do {                                                                                           \
        *out_problem = (msg);                                                                      \
        return (code);                                                                             \
    } while (0)

ak_result akp_rigid_hull_build(ak_vec3_cspan points, void* mem, void* scratch, akp_hull** out_hull,
                               const char** out_problem) {
    static const char* dummy;
    if (!out_problem) out_problem = &dummy;
    *out_problem = "";
    *out_hull = NULL;
    size_t n = points.count;
    if (n && !points.ptr) FAIL(AK_ERR_NULL_ARG, "no points");
    if (n < 4) FAIL(AK_ERR_BAD_ARG, "a hull needs at least 4 points");
    if (n > AK_RIGID_HULL_MAX_POINTS) FAIL(AK_ERR_BAD_ARG, "more points than a hull may have (1024)");
    for (size_t i = 0; i < n; ++i)
        if (!ak_vec3_is_finite(points.ptr[i])) FAIL(AK_ERR_BAD_DATA, "a point is not finite");
    size_t tcap = max_tris(n);
    unsigned char* sp = scratch;
    dv3* p = (dv3*)sp;
    sp += align16(n * sizeof(dv3));
    htri* tris = (htri*)sp;
    sp += align16(tcap * sizeof(htri));
    uint32_t* vis = (uint32_t*)sp;
    sp += align16(tcap * sizeof(uint32_t));
    uint32_t* horizon = (uint32_t*)sp;
    sp += align16(3 * tcap * 2 * sizeof(uint32_t));
    hedge* edges = (hedge*)sp;
    sp += align16(3 * tcap * sizeof(hedge));
    uint32_t* parent = (uint32_t*)sp;
    sp += align16(tcap * sizeof(uint32_t));
    uint32_t* remap = (uint32_t*)sp;
    sp += align16(n * sizeof(uint32_t));
    dv3* gnorm = (dv3*)sp;

    dv3 lo = dv(INFINITY, INFINITY, INFINITY), hi = dv(-INFINITY, -INFINITY, -INFINITY);
    for (size_t i = 0; i < n; ++i) {
        ak_vec3 q = points.ptr[i];
        p[i] = dv(q.x, q.y, q.z);
        lo = dv(fmin(lo.x, q.x), fmin(lo.y, q.y), fmin(lo.z, q.z));
        hi = dv(fmax(hi.x, q.x), fmax(hi.y, q.y), fmax(hi.z, q.z));
    }
    double size = dlen(dsub(hi, lo));
    if (!(size > 0.0)) FAIL(AK_ERR_BAD_ARG, "the points all coincide");
    /* float inputs carry ~6e-8 relative error: points closer than this to a face count as on it */
    double eps = 1e-6 * (size + fmax(dlen(hi), dlen(lo)));

    /* initial tetrahedron: extreme in x, farthest from it, from their line, from their plane */
    uint32_t i0 = 0, i1 = 0, i2 = 0, i3 = 0;
    for (uint32_t i = 1; i < n; ++i)
        if (p[i].x < p[i0].x) i0 = i;
    double best = -1.0;
    for (uint32_t i = 0; i < n; ++i) {
        double d = dlen(dsub(p[i], p[i0]));
        if (d > best) best = d, i1 = i;
    }
    dv3 axis = dscale(dsub(p[i1], p[i0]), 1.0 / best);
    best = -1.0;
    for (uint32_t i = 0; i < n; ++i) {
        dv3 r = dsub(p[i], p[i0]);
        double d = dlen(dsub(r, dscale(axis, ddot(r, axis))));
        if (d > best) best = d, i2 = i;
    }
    if (best <= 100.0 * eps) FAIL(AK_ERR_BAD_ARG, "the points are all on one line");
    dv3 pn = dcross(dsub(p[i1], p[i0]), dsub(p[i2], p[i0]));
    pn = dscale(pn, 1.0 / dlen(pn));
    best = -1.0;
    for (uint32_t i = 0; i < n; ++i) {
        double d = fabs(ddot(dsub(p[i], p[i0]), pn));
        if (d > best) best = d, i3 = i;
    }
    if (best <= 100.0 * eps) FAIL(AK_ERR_BAD_ARG, "the points are all in one plane");
    dv3 inner = dscale(dadd(dadd(p[i0], p[i1]), dadd(p[i2], p[i3])), 0.25);
    const uint32_t tet[4][3] = {{i0, i1, i2}, {i0, i3, i1}, {i1, i3, i2}, {i2, i3, i0}};
    size_t nt = 0;
    for (int f = 0; f < 4; ++f) {
        htri* t = &tris[nt++];
        if (!tri_set(t, p, tet[f][0], tet[f][1], tet[f][2]))
            FAIL(AK_ERR_BAD_ARG, "the points are too nearly in one plane");
        if (ddot(t->n, inner) - t->d > 0.0) tri_set(t, p, tet[f][0], tet[f][2], tet[f][1]);
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (i == i0 || i == i1 || i == i2 || i == i3) continue;
        size_t nv = 0;
        for (size_t t = 0; t < nt; ++t)
            if (ddot(tris[t].n, p[i]) - tris[t].d > eps) vis[nv++] = (uint32_t)t;
        if (nv == 0) continue;
        /* horizon: edges of visible triangles whose twin is not in a visible triangle */
        size_t nh = 0;
        for (size_t a = 0; a < nv; ++a) {
            const htri* ta = &tris[vis[a]];
            for (int k = 0; k < 3; ++k) {
                uint32_t e0 = ta->v[k], e1 = ta->v[(k + 1) % 3];
                bool inner_edge = false;
                for (size_t b = 0; b < nv && !inner_edge; ++b) {
                    if (b == a) continue;
                    const htri* tb = &tris[vis[b]];
                    for (int m = 0; m < 3; ++m)
                        if (tb->v[m] == e1 && tb->v[(m + 1) % 3] == e0) inner_edge = true;
                }
                if (!inner_edge) {
                    if (nh >= 3 * tcap) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate");
                    horizon[2 * nh] = e0, horizon[2 * nh + 1] = e1, ++nh;
                }
            }
        }
        /* remove the visible triangles (vis is increasing: compact from the back) */
        for (size_t a = nv; a-- > 0;) tris[vis[a]] = tris[--nt];
        if (nt + nh > tcap) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate");
        for (size_t h = 0; h < nh; ++h) {
            htri* t = &tris[nt++];
            if (!tri_set(t, p, horizon[2 * h], horizon[2 * h + 1], i) ||
                ddot(t->n, inner) - t->d >= 0.0)
                FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
        }
    }
    /* checks: every point under every face; closed, manifold mesh */
    for (size_t t = 0; t < nt; ++t)
        for (size_t i = 0; i < n; ++i)
            if (ddot(tris[t].n, p[i]) - tris[t].d > 10.0 * eps)
                FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
    size_t ne = 0;
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = tris[t].v[k], b = tris[t].v[(k + 1) % 3];
            edges[ne++] = (hedge){a < b ? a : b, a < b ? b : a, (uint32_t)t};
        }
    qsort(edges, ne, sizeof *edges, hedge_cmp);
    if (ne % 2) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
    for (size_t e = 0; e < ne; e += 2)
        if (edges[e].lo != edges[e + 1].lo || edges[e].hi != edges[e + 1].hi ||
            (e + 2 < ne && edges[e + 2].lo == edges[e].lo && edges[e + 2].hi == edges[e].hi))
            FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
    size_t used = 0;
    for (size_t i = 0; i < n; ++i) remap[i] = UINT32_MAX;
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k)
            if (remap[tris[t].v[k]] == UINT32_MAX) remap[tris[t].v[k]] = (uint32_t)used++;
    if (nt != 2 * used - 4) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");

    /* merge coplanar neighbours into faces */
    for (size_t t = 0; t < nt; ++t) parent[t] = (uint32_t)t;
    for (size_t e = 0; e < ne; e += 2) {
        const htri* a = &tris[edges[e].tri];
        const htri* b = &tris[edges[e + 1].tri];
        double far_b = 0.0, far_a = 0.0;
        for (int k = 0; k < 3; ++k) {
            far_b = fmax(far_b, fabs(ddot(a->n, p[b->v[k]]) - a->d));
            far_a = fmax(far_a, fabs(ddot(b->n, p[a->v[k]]) - b->d));
        }
        if (ddot(a->n, b->n) > 1.0 - 1e-9 && far_a < eps && far_b < eps) {
            uint32_t ra = uf_find(parent, edges[e].tri), rb = uf_find(parent, edges[e + 1].tri);
            if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
        }
    }
    size_t nf = 0;
    for (size_t t = 0; t < nt; ++t)
        if (uf_find(parent, (uint32_t)t) == t) tris[t].group = (uint32_t)nf++;
    for (size_t f = 0; f < nf; ++f) gnorm[f] = dv(0, 0, 0);
    for (size_t t = 0; t < nt; ++t) {
        tris[t].group = tris[uf_find(parent, (uint32_t)t)].group;
        const htri* tr = &tris[t];
        dv3 area = dcross(dsub(p[tr->v[1]], p[tr->v[0]]), dsub(p[tr->v[2]], p[tr->v[0]]));
        gnorm[tr->group] = dadd(gnorm[tr->group], area);
    }

    /* mass properties of the solid: tetrahedra from an interior point o */
    dv3 o = inner;
    double vol = 0.0, cov[3][3] = {{0}};
    dv3 cm = dv(0, 0, 0);
    for (size_t t = 0; t < nt; ++t) {
        dv3 a = dsub(p[tris[t].v[0]], o), b = dsub(p[tris[t].v[1]], o),
            c = dsub(p[tris[t].v[2]], o);
        double v = ddot(a, dcross(b, c)) / 6.0;
        dv3 s = dadd(dadd(a, b), c);
        vol += v;
        cm = dadd(cm, dscale(s, v / 4.0));
        /* integral of x x^T over the tetrahedron (0, a, b, c): v/20 (sum p p^T + s s^T) */
        const double* pa = &a.x;
        const double* pb = &b.x;
        const double* pc = &c.x;
        const double* ps = &s.x;
        for (int r = 0; r < 3; ++r)
            for (int q = 0; q < 3; ++q)
                cov[r][q] += v / 20.0 * (pa[r] * pa[q] + pb[r] * pb[q] + pc[r] * pc[q] + ps[r] * ps[q]);
    }
    if (!(vol > 1e-9 * size * size * size))
        FAIL(AK_ERR_BAD_ARG, "the points are too nearly in one plane (no volume)");
    cm = dscale(cm, 1.0 / vol);
    const double* pcm = &cm.x;
    double inert[3][3];
    double tr = 0.0;
    for (int r = 0; r < 3; ++r) {
        for (int q = 0; q < 3; ++q) cov[r][q] -= vol * pcm[r] * pcm[q];
        tr += cov[r][r];
    }
    for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) inert[r][q] = (r == q ? tr : 0.0) - cov[r][q];
    cm = dadd(cm, o); /* from here on: in the shape frame */
    ak_quat frame;
    ak_vec3 moments;
    akp_rigid_principal(inert, &frame, &moments);
    ak_quat to_body = ak_quat_conjugate(frame);

    /* output */
    unsigned char* mp = mem;
    akp_hull* h = (akp_hull*)mp;
    memset(h, 0, sizeof *h);
    mp += align16(sizeof(akp_hull));
    ak_vec3* verts = (ak_vec3*)mp;
    mp += align16(n * sizeof(ak_vec3));
    akp_hull_face* faces = (akp_hull_face*)mp;
    mp += align16(max_tris(n) * sizeof(akp_hull_face));
    uint32_t* idx = (uint32_t*)mp;
    mp += align16(3 * max_tris(n) * sizeof(uint32_t));
    akp_hull_edge* hedges = (akp_hull_edge*)mp;
    float bound = 0.0f;
    for (size_t i = 0; i < n; ++i) {
        if (remap[i] == UINT32_MAX) continue;
        dv3 r = dsub(p[i], cm);
        ak_vec3 b = ak_quat_rotate(to_body, ak_vec3_make((float)r.x, (float)r.y, (float)r.z));
        verts[remap[i]] = b;
        bound = ak_maxf(bound, ak_vec3_length(b));
    }
    /* each face's boundary: the directed edges of its triangles whose twin is in another face,
     * chained into a loop */
    uint32_t nidx = 0, nedges = 0;
    for (size_t f = 0; f < nf; ++f) {
        akp_hull_face* face = &faces[f];
        dv3 g = gnorm[f];
        ak_vec3 nl = ak_vec3_make((float)g.x, (float)g.y, (float)g.z);
        face->n = ak_vec3_normalize(ak_quat_rotate(to_body, nl));
        face->first = nidx;
        face->count = 0;
    }
    for (size_t e = 0; e < ne; e += 2) {
        uint32_t ta = edges[e].tri, tb = edges[e + 1].tri;
        if (tris[ta].group == tris[tb].group) continue;
        hedges[nedges++] = (akp_hull_edge){remap[edges[e].lo], remap[edges[e].hi], tris[ta].group,
                                           tris[tb].group};
    }
    for (size_t f = 0; f < nf; ++f) {
        akp_hull_face* face = &faces[f];
        face->first = nidx;
        /* the face's boundary edges, directed as its triangles run */
        uint32_t start = UINT32_MAX, count = 0;
        for (size_t e = 0; e < nedges; ++e)
            if (hedges[e].f0 == f || hedges[e].f1 == f) {
                ++count;
                if (start == UINT32_MAX) start = (uint32_t)e;
            }
        if (count < 3) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
        /* orient each boundary edge as the face's triangles run: find it in a triangle */
        uint32_t cur = UINT32_MAX, first_v = UINT32_MAX;
        for (size_t t = 0; t < nt && cur == UINT32_MAX; ++t) {
            if (tris[t].group != f) continue;
            for (int k = 0; k < 3; ++k) {
                uint32_t a = remap[tris[t].v[k]], b = remap[tris[t].v[(k + 1) % 3]];
                const akp_hull_edge* he = &hedges[start];
                if ((he->v0 == a && he->v1 == b) || (he->v0 == b && he->v1 == a)) {
                    first_v = a;
                    cur = b;
                    break;
                }
            }
        }
        if (cur == UINT32_MAX) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
        idx[nidx++] = first_v;
        uint32_t prev = first_v;
        for (uint32_t steps = 1; cur != first_v; ++steps) {
            if (steps > count) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
            idx[nidx++] = cur;
            uint32_t next = UINT32_MAX;
            for (size_t e = 0; e < nedges && next == UINT32_MAX; ++e) {
                const akp_hull_edge* he = &hedges[e];
                if (he->f0 != f && he->f1 != f) continue;
                if (he->v0 == cur && he->v1 != prev) next = he->v1;
                else if (he->v1 == cur && he->v0 != prev) next = he->v0;
            }
            if (next == UINT32_MAX) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
            prev = cur;
            cur = next;
        }
        face->count = nidx - face->first;
        if (face->count != count) FAIL(AK_ERR_BAD_ARG, "the points are too nearly degenerate for a hull");
        float d = -INFINITY;
        for (uint32_t k = 0; k < face->count; ++k)
            d = ak_maxf(d, ak_vec3_dot(face->n, verts[idx[face->first + k]]));
        face->d = d;
    }
    h->verts = verts;
    h->faces = faces;
    h->idx = idx;
    h->edges = hedges;
    h->nv = (uint32_t)used;
    h->nf = (uint32_t)nf;
    h->ne = nedges;
    h->centroid = ak_vec3_make((float)cm.x, (float)cm.y, (float)cm.z);
    h->frame = frame;
    h->volume = vol;
    h->inertia_per_mass = ak_vec3_scale(moments, (float)(1.0 / vol));
    h->bound_radius = bound;
    *out_hull = h;
    return AK_OK;
}

ak_result ak_rigid_hull_check(ak_vec3_cspan points, const char** out_problem) {
    const char* dummy;
    if (!out_problem) out_problem = &dummy;
    *out_problem = "";
    if (points.count > AK_RIGID_HULL_MAX_POINTS || points.count < 4) {
        *out_problem = points.count < 4 ? "a hull needs at least 4 points"
                                        : "more points than a hull may have (1024)";
        return AK_ERR_BAD_ARG;
    }
    if (!points.ptr) {
        *out_problem = "no points";
        return AK_ERR_NULL_ARG;
    }
    size_t ms = akp_rigid_hull_size(points.count), ss = akp_rigid_hull_scratch_size(points.count);
    void* mem = malloc(ms);
    void* scratch = malloc(ss);
    ak_result r = AK_ERR_NO_MEMORY;
    if (mem && scratch) {
        akp_hull* h;
        r = akp_rigid_hull_build(points, mem, scratch, &h, out_problem);
    } else {
        *out_problem = "out of memory";
    }
    free(mem);
    free(scratch);
    return r;
}
