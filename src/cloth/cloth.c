/* Cloth: building the topology and coloured constraints, queries, normals and measures.
 * The step (solvers, forces, collisions, threads) is in step.c. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/mesh.h>

#include "cloth_impl.h"
#include "internal.h"

/* ---- helpers ----------------------------------------------------------------------------- */

/* One triangle edge, for finding unique and interior edges by sorting. */
typedef struct half_edge {
    uint32_t lo, hi;  /* sorted vertex pair */
    uint32_t from;    /* the edge as the triangle walks it: from -> to */
    uint32_t opp;     /* the triangle's third vertex */
} half_edge;

static int half_edge_cmp(const void* a, const void* b) {
    const half_edge *x = (const half_edge*)a, *y = (const half_edge*)b;
    if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi) return x->hi < y->hi ? -1 : 1;
    /* ties: keep a deterministic order */
    if (x->from != y->from) return x->from < y->from ? -1 : 1;
    return x->opp < y->opp ? -1 : (x->opp > y->opp ? 1 : 0);
}

/* A growable array through the allocator. */
typedef struct vec_buf {
    void* ptr;
    size_t count, cap, elem;
} vec_buf;

static bool buf_push(vec_buf* b, const ak_allocator* a, const void* item) {
    if (b->count == b->cap) {
        size_t cap = b->cap ? b->cap * 2 : 256;
        void* p = akp_alloc(a, cap * b->elem);
        if (!p) return false;
        if (b->count) memcpy(p, b->ptr, b->count * b->elem);
        akp_free(a, b->ptr);
        b->ptr = p;
        b->cap = cap;
    }
    memcpy((char*)b->ptr + b->count * b->elem, item, b->elem);
    b->count++;
    return true;
}

static bool nonneg_finite(float x) { return x >= 0.0f && ak_finitef(x); }

static float cot_at(ak_vec3 apex, ak_vec3 a, ak_vec3 b) {
    const ak_vec3 u = ak_vec3_sub(a, apex), v = ak_vec3_sub(b, apex);
    const float s = ak_vec3_length(ak_vec3_cross(u, v));
    return s > 1e-20f ? ak_vec3_dot(u, v) / s : 0.0f;
}

/* Isometric bending of the element x (wings x0, x1, edge x2 -> x3) at rest (Bergou, Wardetzky,
 * Harmon, Zorin, Grinspun 2006): with the edge (x2, x3) as their x0, x1 and c_0j the cotangents of
 * the angles at x2 and x3 in the two triangles, K = (-c01 - c03, -c02 - c04, c03 + c04, c01 + c02)
 * in the order (x0, x1, x2, x3); b = sum K_i x_i vanishes on any flat configuration. */
static bool isometric_weights(const ak_vec3 x[4], float k, akp_bend* e) {
    const float c01 = cot_at(x[2], x[3], x[0]), c02 = cot_at(x[2], x[3], x[1]);
    const float c03 = cot_at(x[3], x[2], x[0]), c04 = cot_at(x[3], x[2], x[1]);
    const float a0 = 0.5f * ak_vec3_length(ak_vec3_cross(ak_vec3_sub(x[3], x[2]), ak_vec3_sub(x[0], x[2])));
    const float a1 = 0.5f * ak_vec3_length(ak_vec3_cross(ak_vec3_sub(x[3], x[2]), ak_vec3_sub(x[1], x[2])));
    if (!(a0 > 1e-20f) || !(a1 > 1e-20f) || !ak_finitef(c01 + c02 + c03 + c04)) return false;
    e->K[0] = -c01 - c03, e->K[1] = -c02 - c04, e->K[2] = c03 + c04, e->K[3] = c01 + c02;
    /* b = sum_{q != 2} K_q (x_q - x_2), as the step computes it (the weights sum to zero) */
    ak_vec3 bv = ak_vec3_make(0, 0, 0);
    for (int q = 0; q < 4; ++q)
        if (q != 2) bv = ak_vec3_add(bv, ak_vec3_scale(ak_vec3_sub(x[q], x[2]), e->K[q]));
    e->rest = ak_vec3_length(bv);
    e->alpha = isinf(k) ? 0.0f : (a0 + a1) / (3.0f * k);
    return true;
}

/* Greedy colouring in input order: the smallest colour none of the constraint's particles has
 * used; AKP_SERIAL_COLOR when all are taken. Writes color[k]. */
static void color_constraints(const uint32_t* parts, size_t stride, size_t count, size_t n, uint64_t* used,
                              uint8_t* color) {
    memset(used, 0, n * sizeof(uint64_t));
    for (size_t k = 0; k < count; ++k) {
        const uint32_t* p = parts + k * stride;
        uint64_t u = 0;
        for (size_t q = 0; q < stride; ++q) u |= used[p[q]];
        int c = AKP_SERIAL_COLOR;
        if (~u) {
            c = 0;
            while (u & ((uint64_t)1 << c)) ++c;
            for (size_t q = 0; q < stride; ++q) used[p[q]] |= (uint64_t)1 << c;
        }
        color[k] = (uint8_t)c;
    }
}

/* The number of colours color[] uses on constraints of stride particles each (parts), or -1 when
 * one colour holds a particle twice (the serial colour counts as one colour and may). */
static int colors_used(const uint32_t* parts, size_t stride, size_t count, size_t n, uint64_t* used,
                       const uint8_t* color) {
    memset(used, 0, n * sizeof(uint64_t));
    uint64_t all = 0;
    bool serial = false;
    for (size_t k = 0; k < count; ++k) {
        if (color[k] >= AKP_SERIAL_COLOR) {
            serial = true;
            continue;
        }
        const uint64_t bit = (uint64_t)1 << color[k];
        for (size_t q = 0; q < stride; ++q) {
            if (used[parts[k * stride + q]] & bit) return -1;
            used[parts[k * stride + q]] |= bit;
        }
        all |= bit;
    }
    int c = serial;
    for (; all; all &= all - 1) ++c;
    return c;
}

/* The distance constraints of a grid (stretch, shear, and bending springs two apart): 2 colours
 * per direction (the parity of the start along it; for the springs two apart, of half of it),
 * 12 with bending springs, which is the fewest (12 constraints meet at an inner vertex) where
 * greedy takes 13. Writes color[k]; false when a constraint is not one of the grid's. */
static bool color_grid_dists(const uint32_t* parts, size_t nd, uint32_t w, uint8_t* color) {
    for (size_t k = 0; k < nd; ++k) {
        const uint32_t a = parts[2 * k] < parts[2 * k + 1] ? parts[2 * k] : parts[2 * k + 1];
        const uint32_t b = parts[2 * k] < parts[2 * k + 1] ? parts[2 * k + 1] : parts[2 * k];
        const uint32_t i = a % w, j = a / w;
        int c;
        if (b == a + 1 && i + 1 < w) c = 0 + (int)(i & 1);
        else if (b == a + w) c = 2 + (int)(j & 1);
        else if (b == a + w + 1 && i + 1 < w) c = 4 + (int)(i & 1);
        else if (b == a + w - 1 && i > 0) c = 6 + (int)(i & 1);
        else if (b == a + 2 && i + 2 < w) c = 8 + (int)((i >> 1) & 1);
        else if (b == a + 2 * w) c = 10 + (int)((j >> 1) & 1);
        else return false;
        color[k] = (uint8_t)c;
    }
    return true;
}

/* The bending elements of a grid (build_topology: w x h vertices, the diagonal alternating with
 * the cell's parity, "union jack") in 16 colours, which is the fewest there can
 * be: a vertex (i, j) with i + j even (inside the grid) is on 8 edges and 8 triangles, so 16
 * elements hold it (8 along an edge, 8 as a wing opposite one of its triangles) and no two of them
 * can share a colour. Seen from the lattice of even vertices (u, v) = ((i + j) / 2, (i - j) / 2),
 * whose unit squares are the odd vertices:
 * - a diagonal's element is the four corners of its grid cell: colour by the cell's (i mod 2,
 *   j mod 2) (4 colours, each a perfect tiling of the vertices);
 * - an edge along the grid joins an odd vertex (a square of the lattice) to one even vertex, and
 *   its wings are the even vertices beside it: the element is 3 corners of the square (an L
 *   tromino) plus the odd vertex itself. A horizontal edge leaves out the square's W or E corner,
 *   a vertical one its N or S corner. Two trominoes, (U, V) without E and (U + 1, V) without W,
 *   tile a 3 x 2 block of lattice vertices, and the block's 6 translates (U mod 3, V mod 2) give
 *   every square its E-less and W-less tromino once: 6 colours for the horizontal edges, and the
 *   mirror image (squares U + 1 without S, U + 2 without N) 6 more for the vertical ones.
 * Writes color[k] for the nb elements (corners p[0..3], edge p[2] -> p[3]); false when an element
 * is not one of the grid's (the caller then colours greedily). */
static bool color_grid_bends(const akp_bend* bs, size_t nb, uint32_t w, uint32_t h, uint8_t* color) {
    for (size_t k = 0; k < nb; ++k) {
        const uint32_t a = bs[k].p[2] < bs[k].p[3] ? bs[k].p[2] : bs[k].p[3];
        const uint32_t b = bs[k].p[2] < bs[k].p[3] ? bs[k].p[3] : bs[k].p[2];
        const int64_t i = a % w, j = a / w;
        if (b == a + w + 1 || (i > 0 && b == a + w - 1)) {
            const int64_t ci = b == a + w + 1 ? i : i - 1; /* the diagonal's cell (ci, j) */
            color[k] = (uint8_t)((ci & 1) | ((j & 1) << 1));
            continue;
        }
        const bool horiz = b == a + 1 && i + 1 < w;
        if (!horiz && b != a + w) return false;
        /* the odd endpoint (x, y) and the corner its element leaves out */
        const bool a_odd = (i + j) & 1;
        const int64_t x = a_odd ? i : (horiz ? i + 1 : i), y = a_odd ? j : (horiz ? j : j + 1);
        /* lattice square (U, V) of the odd vertex: corners W (U, V), N (U, V + 1), S (U + 1, V),
         * E (U + 1, V + 1); V shifted by h to stay non-negative */
        const int64_t U = (x + y - 1) / 2, V = (x - y - 1 + 2 * (int64_t)h) / 2;
        int64_t sq; /* the tromino's square within its 3 x 2 block */
        int base;
        if (horiz) { /* a odd: the even endpoint is east, W is left out (square 1); else E (0) */
            sq = a_odd ? 1 : 0;
            base = 4;
        } else {     /* a odd: the even endpoint is south, N is left out (square 2); else S (1) */
            sq = a_odd ? 2 : 1;
            base = 10;
        }
        const int64_t t = ((U - sq) % 3 + 3) % 3;
        color[k] = (uint8_t)(base + 2 * t + (V & 1));
    }
    return true;
}

/* Stable counting sort of elements (elem bytes each) by colour into dst; fills start[]. */
static void sort_by_color(const void* src, void* dst, size_t elem, size_t count, const uint8_t* color,
                          uint32_t start[AKP_MAX_COLORS + 2]) {
    uint32_t cnt[AKP_MAX_COLORS + 1] = {0};
    for (size_t k = 0; k < count; ++k) cnt[color[k]]++;
    start[0] = 0;
    for (int c = 0; c <= AKP_MAX_COLORS; ++c) start[c + 1] = start[c] + cnt[c];
    uint32_t pos[AKP_MAX_COLORS + 1];
    memcpy(pos, start, sizeof pos);
    for (size_t k = 0; k < count; ++k)
        memcpy((char*)dst + (size_t)pos[color[k]]++ * elem, (const char*)src + k * elem, elem);
}

/* ---- desc ------------------------------------------------------------------------------- */

ak_cloth_desc ak_cloth_desc_resolved(const ak_cloth_desc* desc) {
    ak_cloth_desc d;
    if (desc) d = *desc;
    else memset(&d, 0, sizeof d);
    if (d.spacing == 0.0f) d.spacing = 0.05f;
    if (ak_vec3_length_sq(d.grid_axis_u) == 0.0f) d.grid_axis_u = ak_vec3_make(1, 0, 0);
    if (ak_vec3_length_sq(d.grid_axis_v) == 0.0f) d.grid_axis_v = ak_vec3_make(0, 0, -1);
    d.grid_axis_u = ak_vec3_normalize(d.grid_axis_u);
    d.grid_axis_v = ak_vec3_normalize(d.grid_axis_v);
    if (d.area_density == 0.0f) d.area_density = 0.2f;
    if (d.stretch_stiffness == 0.0f) d.stretch_stiffness = 5000.0f;
    if (d.shear_stiffness == 0.0f) d.shear_stiffness = d.stretch_stiffness;
    if (d.bend_stiffness == 0.0f) d.bend_stiffness = d.stretch_stiffness / 100.0f;
    if (d.dihedral_stiffness == 0.0f) d.dihedral_stiffness = 1e-4f;
    if (d.bending == AK_CLOTH_BEND_DEFAULT)
        d.bending = akp_spring_solver(d.solver) ? AK_CLOTH_BEND_SPRINGS : AK_CLOTH_BEND_DIHEDRAL;
    if (akp_spring_solver(d.solver) && (d.bending == AK_CLOTH_BEND_DIHEDRAL || d.bending == AK_CLOTH_BEND_ISOMETRIC))
        d.bending = AK_CLOTH_BEND_SPRINGS;
    if (d.pbd_stiffness == 0.0f) d.pbd_stiffness = 1.0f;
    return d;
}

static ak_result check_desc(const ak_cloth_desc* d, const ak_allocator* alloc) {
    if ((unsigned)d->solver >= AK_CLOTH_SOLVER_COUNT || (unsigned)d->bending >= AK_CLOTH_BENDING_COUNT)
        return AK_ERR_BAD_ARG;
    if (alloc && ((alloc->alloc == NULL) != (alloc->free == NULL))) return AK_ERR_BAD_ARG;
    const float ks[4] = {d->stretch_stiffness, d->shear_stiffness, d->bend_stiffness, d->dihedral_stiffness};
    for (int k = 0; k < 4; ++k) {
        if (!(ks[k] > 0.0f)) return AK_ERR_BAD_ARG; /* negative or NaN (0 was resolved) */
        if (isinf(ks[k]) && akp_spring_solver(d->solver)) return AK_ERR_BAD_ARG;
    }
    if (!nonneg_finite(d->spring_damping) || !nonneg_finite(d->constraint_damping) ||
        !nonneg_finite(d->long_range_slack) || !(d->area_density > 0.0f) || !ak_finitef(d->area_density) ||
        !(d->pbd_stiffness > 0.0f && d->pbd_stiffness <= 1.0f) || !(d->spacing > 0.0f) || !ak_finitef(d->spacing))
        return AK_ERR_BAD_ARG;
    if (d->indices.count % 3 || d->edges.count % 2) return AK_ERR_BAD_ARG;
    if ((d->indices.count && !d->indices.ptr) || (d->edges.count && !d->edges.ptr) || (d->pins.count && !d->pins.ptr) ||
        (d->attachments.count && !d->attachments.ptr) || (d->pin_positions.count && !d->pin_positions.ptr) ||
        (d->inverse_masses.count && !d->inverse_masses.ptr))
        return AK_ERR_NULL_ARG;
    if (d->pin_positions.count && d->pin_positions.count != d->pins.count) return AK_ERR_BAD_ARG;
    return AK_OK;
}

/* The spring solver's stable substep (ak_cloth_stable_substep): Gershgorin row sums per
 * particle in row[n] (caller's memory), in double. */
static float spring_stable_h(const ak_cloth* c, double* row) {
    double omega2 = 0.0, gamma = 0.0;
    for (int pass = 0; pass < 2; ++pass) {
        memset(row, 0, c->n * sizeof(double));
        for (size_t k = 0; k < c->dist_count; ++k) {
            const akp_dist* d = &c->dist[k];
            const double wi = c->inv_mass[d->i], wj = c->inv_mass[d->j], x = sqrt(wi * wj);
            const double s = pass ? (double)c->desc.spring_damping : (double)d->k;
            row[d->i] += s * (wi + x);
            row[d->j] += s * (wj + x);
        }
        double m = 0.0;
        for (size_t v = 0; v < c->n; ++v) m = fmax(m, row[v]);
        if (pass) gamma = m;
        else omega2 = m;
    }
    if (!(omega2 > 0.0) || !isfinite(omega2)) return INFINITY;
    return (float)((sqrt(gamma * gamma + 4.0 * omega2) - gamma) / omega2);
}

/* ---- create ----------------------------------------------------------------------------- */

typedef struct build {
    const ak_allocator* a;
    size_t n, tri_count;
    ak_vec3* rest;
    uint32_t* tris;
    float* inv_mass;
    vec_buf dist, bend;
} build;

static void build_free(build* b) {
    akp_free(b->a, b->rest);
    akp_free(b->a, b->tris);
    akp_free(b->a, b->inv_mass);
    akp_free(b->a, b->dist.ptr);
    akp_free(b->a, b->bend.ptr);
}

static bool add_dist(build* b, const ak_cloth_desc* d, uint32_t i, uint32_t j, uint32_t kind) {
    const float k = kind == AKP_STRETCH ? d->stretch_stiffness : kind == AKP_SHEAR ? d->shear_stiffness : d->bend_stiffness;
    akp_dist c = {i, j, ak_vec3_distance(b->rest[i], b->rest[j]), k, isinf(k) ? 0.0f : 1.0f / k, kind};
    return buf_push(&b->dist, b->a, &c);
}

/* Topology of the grid or mesh into b (rest, tris). */
static ak_result build_topology(build* b, const ak_cloth_desc* d) {
    if (d->positions.count == 0) {
        const uint32_t w = d->grid_width, h = d->grid_height;
        if (w == 0 && h == 0) return AK_ERR_EMPTY;
        if (w < 2 || h < 2 || (uint64_t)w * h > ((uint64_t)1 << 24)) return AK_ERR_BAD_ARG;
        if (!ak_vec3_is_finite(d->grid_origin) || !ak_vec3_is_finite(d->grid_axis_u) || !ak_vec3_is_finite(d->grid_axis_v))
            return AK_ERR_BAD_DATA;
        b->n = (size_t)w * h;
        b->tri_count = (size_t)(w - 1) * (h - 1) * 2;
        b->rest = akp_alloc(b->a, b->n * sizeof(ak_vec3));
        b->tris = akp_alloc(b->a, b->tri_count * 3 * sizeof(uint32_t));
        if (!b->rest || !b->tris) return AK_ERR_NO_MEMORY;
        for (uint32_t j = 0; j < h; ++j)
            for (uint32_t i = 0; i < w; ++i)
                b->rest[(size_t)j * w + i] = ak_vec3_add(d->grid_origin,
                                                         ak_vec3_add(ak_vec3_scale(d->grid_axis_u, (float)i * d->spacing),
                                                                     ak_vec3_scale(d->grid_axis_v, (float)j * d->spacing)));
        size_t t = 0;
        for (uint32_t j = 0; j + 1 < h; ++j)
            for (uint32_t i = 0; i + 1 < w; ++i) {
                const uint32_t a = j * w + i, bb = a + 1, c = a + w, dd = c + 1;
                uint32_t* o = b->tris + 6 * t++;
                if ((i + j) & 1) { /* alternate the diagonal: a symmetric pattern */
                    o[0] = a, o[1] = bb, o[2] = c, o[3] = bb, o[4] = dd, o[5] = c;
                } else {
                    o[0] = a, o[1] = bb, o[2] = dd, o[3] = a, o[4] = dd, o[5] = c;
                }
            }
        return AK_OK;
    }
    if (!d->positions.ptr) return AK_ERR_NULL_ARG;
    if (d->positions.count > ((size_t)1 << 31)) return AK_ERR_BAD_ARG;
    b->n = d->positions.count;
    b->tri_count = d->indices.count / 3;
    if (b->tri_count == 0 && d->edges.count == 0) return AK_ERR_EMPTY;
    for (size_t v = 0; v < b->n; ++v)
        if (!ak_vec3_is_finite(d->positions.ptr[v])) return AK_ERR_BAD_DATA;
    for (size_t t = 0; t < b->tri_count; ++t) {
        const uint32_t* o = d->indices.ptr + 3 * t;
        if (o[0] >= b->n || o[1] >= b->n || o[2] >= b->n) return AK_ERR_BAD_INDEX;
        if (o[0] == o[1] || o[1] == o[2] || o[0] == o[2]) return AK_ERR_BAD_INDEX;
    }
    b->rest = akp_alloc(b->a, b->n * sizeof(ak_vec3));
    b->tris = b->tri_count ? akp_alloc(b->a, b->tri_count * 3 * sizeof(uint32_t)) : NULL;
    if (!b->rest || (b->tri_count && !b->tris)) return AK_ERR_NO_MEMORY;
    memcpy(b->rest, d->positions.ptr, b->n * sizeof(ak_vec3));
    if (b->tri_count) memcpy(b->tris, d->indices.ptr, b->tri_count * 3 * sizeof(uint32_t));
    return AK_OK;
}

static ak_result build_masses(build* b, const ak_cloth_desc* d) {
    b->inv_mass = akp_calloc(b->a, b->n * sizeof(float));
    if (!b->inv_mass) return AK_ERR_NO_MEMORY;
    if (d->inverse_masses.count) {
        if (d->inverse_masses.count != b->n) return AK_ERR_BAD_ARG;
        for (size_t v = 0; v < b->n; ++v) {
            const float w = d->inverse_masses.ptr[v];
            if (!(w >= 0.0f) || !ak_finitef(w)) return AK_ERR_BAD_DATA;
            b->inv_mass[v] = w;
        }
    } else {
        /* lumped: a third of each triangle's mass on each corner (accumulated in inv_mass) */
        for (size_t t = 0; t < b->tri_count; ++t) {
            const uint32_t* o = b->tris + 3 * t;
            const float area = 0.5f * ak_vec3_length(ak_vec3_cross(ak_vec3_sub(b->rest[o[1]], b->rest[o[0]]),
                                                                    ak_vec3_sub(b->rest[o[2]], b->rest[o[0]])));
            for (int k = 0; k < 3; ++k) b->inv_mass[o[k]] += area * d->area_density / 3.0f;
        }
        for (size_t v = 0; v < b->n; ++v) {
            if (!(b->inv_mass[v] > 0.0f)) return AK_ERR_BAD_ARG; /* on no (or only degenerate) triangles */
            b->inv_mass[v] = 1.0f / b->inv_mass[v];
        }
    }
    /* pins and attachments: kinematic, each vertex listed once */
    for (size_t k = 0; k < d->pins.count + d->attachments.count; ++k) {
        const uint32_t v = k < d->pins.count ? d->pins.ptr[k] : d->attachments.ptr[k - d->pins.count];
        if (v >= b->n || b->inv_mass[v] < 0.0f) return AK_ERR_BAD_INDEX;
        b->inv_mass[v] = -1.0f; /* mark */
    }
    for (size_t k = 0; k < d->pin_positions.count; ++k)
        if (!ak_vec3_is_finite(d->pin_positions.ptr[k])) return AK_ERR_BAD_DATA;
    for (size_t v = 0; v < b->n; ++v)
        if (b->inv_mass[v] < 0.0f) b->inv_mass[v] = 0.0f;
    return AK_OK;
}

static ak_result build_constraints(build* b, const ak_cloth_desc* d) {
    b->dist.elem = sizeof(akp_dist);
    b->bend.elem = sizeof(akp_bend);
    const bool grid = d->positions.count == 0;
    /* interior edges of the triangle mesh (grid or given) */
    half_edge* he = NULL;
    const size_t hn = b->tri_count * 3;
    if (hn) {
        he = akp_alloc(b->a, hn * sizeof(half_edge));
        if (!he) return AK_ERR_NO_MEMORY;
        for (size_t t = 0; t < b->tri_count; ++t)
            for (int k = 0; k < 3; ++k) {
                const uint32_t p = b->tris[3 * t + k], q = b->tris[3 * t + (k + 1) % 3], r = b->tris[3 * t + (k + 2) % 3];
                he[3 * t + k] = (half_edge){p < q ? p : q, p < q ? q : p, p, r};
            }
        qsort(he, hn, sizeof(half_edge), half_edge_cmp);
    }
    bool ok = true;
    if (grid) {
        const uint32_t w = d->grid_width, h = d->grid_height;
        for (uint32_t j = 0; j < h && ok; ++j)
            for (uint32_t i = 0; i < w && ok; ++i) {
                const uint32_t a = j * w + i;
                if (i + 1 < w) ok = ok && add_dist(b, d, a, a + 1, AKP_STRETCH);
                if (j + 1 < h) ok = ok && add_dist(b, d, a, a + w, AKP_STRETCH);
                if (i + 1 < w && j + 1 < h) {
                    ok = ok && add_dist(b, d, a, a + w + 1, AKP_SHEAR);
                    ok = ok && add_dist(b, d, a + 1, a + w, AKP_SHEAR);
                }
                if (d->bending == AK_CLOTH_BEND_SPRINGS) {
                    if (i + 2 < w) ok = ok && add_dist(b, d, a, a + 2, AKP_BEND);
                    if (j + 2 < h) ok = ok && add_dist(b, d, a, a + 2 * w, AKP_BEND);
                }
            }
    } else {
        for (size_t k = 0; k < hn && ok; ++k)
            if (k == 0 || he[k].lo != he[k - 1].lo || he[k].hi != he[k - 1].hi)
                ok = add_dist(b, d, he[k].lo, he[k].hi, AKP_STRETCH);
    }
    /* bending across interior edges (the first two triangles of an edge) */
    for (size_t k = 0; k + 1 < hn && ok; ++k) {
        if (he[k].lo != he[k + 1].lo || he[k].hi != he[k + 1].hi) continue;
        if (k > 0 && he[k].lo == he[k - 1].lo && he[k].hi == he[k - 1].hi) continue;
        if (he[k].opp == he[k + 1].opp) continue;
        if (d->bending == AK_CLOTH_BEND_DIHEDRAL || d->bending == AK_CLOTH_BEND_ISOMETRIC) {
            /* triangle A walks p2 -> p3 with wing p0: (p2, p3, p0) */
            const uint32_t p2 = he[k].from, p3 = he[k].from == he[k].lo ? he[k].hi : he[k].lo;
            akp_bend e = {{he[k].opp, he[k + 1].opp, p2, p3}, 0.0f, {0, 0, 0, 0}, 0.0f};
            /* the second triangle must walk the edge the other way (consistent orientation);
             * otherwise its wing's sign flips: skip such edges (non-orientable neighbourhoods) */
            if (he[k + 1].from == p2) continue;
            ak_vec3 x[4];
            for (int q = 0; q < 4; ++q) x[q] = b->rest[e.p[q]];
            if (d->bending == AK_CLOTH_BEND_DIHEDRAL) {
                e.rest = akp_dihedral(x, NULL);
            } else if (!isometric_weights(x, d->dihedral_stiffness, &e)) {
                continue; /* a degenerate triangle: no bending there */
            }
            ok = buf_push(&b->bend, b->a, &e);
        } else if (d->bending == AK_CLOTH_BEND_SPRINGS && !grid) {
            ok = add_dist(b, d, he[k].opp, he[k + 1].opp, AKP_BEND);
        }
    }
    akp_free(b->a, he);
    for (size_t k = 0; k < d->edges.count / 2 && ok; ++k) {
        const uint32_t i = d->edges.ptr[2 * k], j = d->edges.ptr[2 * k + 1];
        if (i >= b->n || j >= b->n || i == j) return AK_ERR_BAD_INDEX;
        ok = add_dist(b, d, i, j, AKP_STRETCH);
    }
    return ok ? AK_OK : AK_ERR_NO_MEMORY;
}

ak_result ak_cloth_create(const ak_cloth_desc* desc_in, const ak_allocator* alloc, ak_cloth** out_cloth) {
    if (out_cloth) *out_cloth = NULL;
    if (!desc_in || !out_cloth) return AK_ERR_NULL_ARG;
    const ak_cloth_desc d = ak_cloth_desc_resolved(desc_in);
    ak_result r = check_desc(&d, alloc);
    if (r != AK_OK) return r;
    const ak_allocator* a = (alloc && alloc->alloc) ? alloc : NULL;
    build b = {.a = a};
    if ((r = build_topology(&b, &d)) != AK_OK || (r = build_masses(&b, &d)) != AK_OK ||
        (r = build_constraints(&b, &d)) != AK_OK) {
        build_free(&b);
        return r;
    }
    const size_t n = b.n, nd = b.dist.count, nb = b.bend.count, nt = b.tri_count;
    const size_t np = d.pins.count, na = d.attachments.count;
    const bool lra = d.long_range_attachments && !akp_spring_solver(d.solver);
    size_t size = akp_align16(sizeof(ak_cloth));
    const size_t s_rest = size; size += akp_align16(n * sizeof(ak_vec3));
    const size_t s_inv = size; size += akp_align16(n * sizeof(float));
    const size_t s_mass = size; size += akp_align16(n * sizeof(float));
    const size_t s_tri = size; size += akp_align16(nt * 3 * sizeof(uint32_t));
    const size_t s_pins = size; size += akp_align16(np * sizeof(uint32_t));
    const size_t s_pinp = size; size += akp_align16(np * sizeof(ak_vec3));
    const size_t s_att = size; size += akp_align16(na * sizeof(uint32_t));
    const size_t s_dist = size; size += akp_align16(nd * sizeof(akp_dist));
    const size_t s_bend = size; size += akp_align16(nb * sizeof(akp_bend));
    const bool iso = d.bending == AK_CLOTH_BEND_ISOMETRIC;
    const size_t s_dsoa = size; size += 4 * akp_align16(nd * sizeof(float));
    const size_t s_bsoa = size; size += (iso ? 10 : 5) * akp_align16(nb * sizeof(float));
    const size_t s_lra = size; size += lra ? akp_align16(n * sizeof(uint32_t)) : 0;
    const size_t s_lrad = size; size += lra ? akp_align16(n * sizeof(float)) : 0;
    const size_t s_vts = size; size += akp_align16((n + 1) * sizeof(uint32_t));
    const size_t s_vtt = size; size += akp_align16(nt * 3 * sizeof(uint32_t));
    /* colouring scratch */
    const size_t colors_n = nd > nb ? nd : nb;
    uint64_t* used = akp_alloc(a, n * sizeof(uint64_t));
    uint8_t* color = akp_alloc(a, 2 * (colors_n ? colors_n : 1));
    uint32_t* parts = akp_alloc(a, (colors_n ? colors_n : 1) * 4 * sizeof(uint32_t));
    char* mem = akp_calloc(a, size);
    if (!used || !color || !parts || !mem) {
        akp_free(a, used), akp_free(a, color), akp_free(a, parts), akp_free(a, mem);
        build_free(&b);
        return AK_ERR_NO_MEMORY;
    }
    uint8_t* color2 = color + (colors_n ? colors_n : 1); /* a second colouring to compare */
    ak_cloth* c = (ak_cloth*)mem;
    c->alloc = a ? *a : (ak_allocator){0};
    c->n = n, c->tri_count = nt, c->dist_count = nd, c->bend_count = nb, c->attach_count = na, c->pin_count = np;
    c->rest = (ak_vec3*)(mem + s_rest);
    c->inv_mass = (float*)(mem + s_inv);
    c->mass = (float*)(mem + s_mass);
    c->indices = (uint32_t*)(mem + s_tri);
    c->pins = (uint32_t*)(mem + s_pins);
    c->pin_pos = (ak_vec3*)(mem + s_pinp);
    c->attach = (uint32_t*)(mem + s_att);
    c->dist = (akp_dist*)(mem + s_dist);
    c->bend = (akp_bend*)(mem + s_bend);
    c->lra_anchor = lra ? (uint32_t*)(mem + s_lra) : NULL;
    c->lra_dist = lra ? (float*)(mem + s_lrad) : NULL;
    c->vt_start = (uint32_t*)(mem + s_vts);
    c->vt_tri = (uint32_t*)(mem + s_vtt);
    memcpy(c->rest, b.rest, n * sizeof(ak_vec3));
    memcpy(c->inv_mass, b.inv_mass, n * sizeof(float));
    for (size_t v = 0; v < n; ++v) c->mass[v] = b.inv_mass[v] > 0.0f ? 1.0f / b.inv_mass[v] : 0.0f;
    if (nt) memcpy(c->indices, b.tris, nt * 3 * sizeof(uint32_t));
    for (size_t k = 0; k < np; ++k) {
        c->pins[k] = d.pins.ptr[k];
        c->pin_pos[k] = d.pin_positions.count ? d.pin_positions.ptr[k] : b.rest[d.pins.ptr[k]];
    }
    for (size_t k = 0; k < na; ++k) c->attach[k] = d.attachments.ptr[k];
    /* colour and sort the constraints */
    const akp_dist* ds = (const akp_dist*)b.dist.ptr;
    for (size_t k = 0; k < nd; ++k) parts[2 * k] = ds[k].i, parts[2 * k + 1] = ds[k].j;
    color_constraints(parts, 2, nd, n, used, color);
    if (d.positions.count == 0 && color_grid_dists(parts, nd, d.grid_width, color2)) {
        /* the grid's structured colouring where it takes fewer colours than greedy (bending
         * springs: 12 against 13; otherwise both take 8 and greedy's order stays) */
        const int s = colors_used(parts, 2, nd, n, used, color2);
        if (s > 0 && s < colors_used(parts, 2, nd, n, used, color)) memcpy(color, color2, nd);
    }
    sort_by_color(ds, c->dist, sizeof(akp_dist), nd, color, c->dist_color);
    const akp_bend* bs = (const akp_bend*)b.bend.ptr;
    for (size_t k = 0; k < nb; ++k) memcpy(parts + 4 * k, bs[k].p, 4 * sizeof(uint32_t));
    /* the grid's elements: the structured colouring, checked here (falling back to greedy) */
    const bool colored = d.positions.count == 0 && color_grid_bends(bs, nb, d.grid_width, d.grid_height, color) &&
                         colors_used(parts, 4, nb, n, used, color) >= 0;
    if (!colored) color_constraints(parts, 4, nb, n, used, color);
    sort_by_color(bs, c->bend, sizeof(akp_bend), nb, color, c->bend_color);
    /* the solvers' structure-of-arrays copies, in the same (colour) order */
    {
        const size_t sd = akp_align16(nd * sizeof(float)), sb = akp_align16(nb * sizeof(float));
        c->dist_i = (uint32_t*)(mem + s_dsoa);
        c->dist_j = (uint32_t*)(mem + s_dsoa + sd);
        c->dist_rest = (float*)(mem + s_dsoa + 2 * sd);
        c->dist_alpha = (float*)(mem + s_dsoa + 3 * sd);
        for (size_t k = 0; k < nd; ++k) {
            c->dist_i[k] = c->dist[k].i, c->dist_j[k] = c->dist[k].j;
            c->dist_rest[k] = c->dist[k].rest, c->dist_alpha[k] = c->dist[k].alpha;
        }
        for (int q = 0; q < 4; ++q) {
            c->bend_p[q] = (uint32_t*)(mem + s_bsoa + (size_t)q * sb);
            c->bend_K[q] = iso ? (float*)(mem + s_bsoa + (size_t)(5 + q) * sb) : NULL;
        }
        c->bend_rest = (float*)(mem + s_bsoa + 4 * sb);
        c->bend_alpha = iso ? (float*)(mem + s_bsoa + 9 * sb) : NULL;
        for (size_t k = 0; k < nb; ++k) {
            for (int q = 0; q < 4; ++q) {
                c->bend_p[q][k] = c->bend[k].p[q];
                if (iso) c->bend_K[q][k] = c->bend[k].K[q];
            }
            c->bend_rest[k] = c->bend[k].rest;
            if (iso) c->bend_alpha[k] = c->bend[k].alpha;
        }
    }
    /* long-range attachments: the nearest kinematic particle at rest */
    if (lra) {
        for (size_t v = 0; v < n; ++v) {
            c->lra_anchor[v] = UINT32_MAX;
            c->lra_dist[v] = 0.0f;
            if (c->inv_mass[v] == 0.0f) continue;
            float best = INFINITY;
            for (size_t u = 0; u < n; ++u) {
                if (c->inv_mass[u] != 0.0f) continue;
                const float dd = ak_vec3_distance(c->rest[u], c->rest[v]);
                if (dd < best) best = dd, c->lra_anchor[v] = (uint32_t)u;
            }
            c->lra_dist[v] = best * (1.0f + d.long_range_slack);
        }
    }
    c->desc = d; /* (the spans are set below) */
    c->stable_h = spring_stable_h(c, (double*)used); /* n uint64 hold n doubles */
    /* vertex -> triangles (CSR, each vertex's triangles in increasing order) */
    for (size_t k = 0; k < nt * 3; ++k) c->vt_start[c->indices[k] + 1]++;
    for (size_t v = 0; v < n; ++v) c->vt_start[v + 1] += c->vt_start[v];
    uint32_t* cursor = (uint32_t*)used; /* n uint64 hold n uint32 */
    memcpy(cursor, c->vt_start, n * sizeof(uint32_t));
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) c->vt_tri[cursor[c->indices[3 * t + k]]++] = (uint32_t)t;
    akp_free(a, used), akp_free(a, color), akp_free(a, parts);
    /* desc copy with spans at the cloth's own arrays */
    c->desc = d;
    c->desc.positions = (ak_vec3_cspan){NULL, 0};
    c->desc.indices = (ak_u32_cspan){c->indices, nt * 3};
    c->desc.edges = (ak_u32_cspan){NULL, 0};
    c->desc.inverse_masses = (ak_f32_cspan){c->inv_mass, n};
    c->desc.pins = (ak_u32_cspan){c->pins, np};
    c->desc.pin_positions = (ak_vec3_cspan){c->pin_pos, np};
    c->desc.attachments = (ak_u32_cspan){c->attach, na};
    build_free(&b);
    *out_cloth = c;
    return AK_OK;
}

void ak_cloth_destroy(ak_cloth* cloth) {
    if (!cloth) return;
    const ak_allocator a = cloth->alloc;
    akp_free(a.alloc ? &a : NULL, cloth);
}

size_t ak_cloth_vertex_count(const ak_cloth* cloth) { return cloth ? cloth->n : 0; }
size_t ak_cloth_triangle_count(const ak_cloth* cloth) { return cloth ? cloth->tri_count : 0; }
ak_u32_cspan ak_cloth_indices(const ak_cloth* cloth) {
    return cloth ? (ak_u32_cspan){cloth->indices, cloth->tri_count * 3} : (ak_u32_cspan){NULL, 0};
}
ak_f32_cspan ak_cloth_inverse_masses(const ak_cloth* cloth) {
    return cloth ? (ak_f32_cspan){cloth->inv_mass, cloth->n} : (ak_f32_cspan){NULL, 0};
}
size_t ak_cloth_attachment_count(const ak_cloth* cloth) { return cloth ? cloth->attach_count : 0; }
ak_cloth_desc ak_cloth_get_desc(const ak_cloth* cloth) {
    if (cloth) return cloth->desc;
    ak_cloth_desc d;
    memset(&d, 0, sizeof d);
    return d;
}

ak_result ak_cloth_rest_positions(const ak_cloth* cloth, ak_vec3_span out_positions) {
    if (!cloth || !out_positions.ptr) return AK_ERR_NULL_ARG;
    if (out_positions.count < cloth->n) return AK_ERR_SPAN_SMALL;
    memcpy(out_positions.ptr, cloth->rest, cloth->n * sizeof(ak_vec3));
    for (size_t k = 0; k < cloth->pin_count; ++k) out_positions.ptr[cloth->pins[k]] = cloth->pin_pos[k];
    return AK_OK;
}

float ak_cloth_stable_substep(const ak_cloth* cloth) {
    if (!cloth) return 0.0f;
    return cloth->desc.solver == AK_CLOTH_SPRINGS ? cloth->stable_h : INFINITY;
}

ak_result ak_cloth_normals(const ak_cloth* cloth, ak_vec3_cspan positions, ak_vec3_span out_normals) {
    if (!cloth || !positions.ptr || !out_normals.ptr) return AK_ERR_NULL_ARG;
    if (positions.count != cloth->n) return AK_ERR_BAD_ARG;
    if (out_normals.count < cloth->n) return AK_ERR_SPAN_SMALL;
    /* gather per vertex over its triangles in a fixed order (the same sum as step.c's) */
    for (size_t v = 0; v < cloth->n; ++v) {
        ak_vec3 s = ak_vec3_make(0, 0, 0);
        for (uint32_t k = cloth->vt_start[v]; k < cloth->vt_start[v + 1]; ++k) {
            const uint32_t* o = cloth->indices + 3 * cloth->vt_tri[k];
            const ak_vec3 a = positions.ptr[o[0]];
            s = ak_vec3_add(s, ak_vec3_cross(ak_vec3_sub(positions.ptr[o[1]], a), ak_vec3_sub(positions.ptr[o[2]], a)));
        }
        const float l = ak_vec3_length(s);
        out_normals.ptr[v] = l > 1e-30f && ak_finitef(l) ? ak_vec3_scale(s, 1.0f / l) : ak_vec3_make(0, 1, 0);
    }
    return AK_OK;
}

float ak_cloth_max_stretch(const ak_cloth* cloth, ak_vec3_cspan positions) {
    if (!cloth || !positions.ptr || positions.count != cloth->n) return 0.0f;
    float m = 0.0f;
    for (size_t k = 0; k < cloth->dist_count; ++k) {
        const akp_dist* c = &cloth->dist[k];
        if (c->kind != AKP_STRETCH || c->rest <= 0.0f) continue;
        const float s = ak_vec3_distance(positions.ptr[c->i], positions.ptr[c->j]) / c->rest - 1.0f;
        if (!ak_finitef(s)) return NAN;
        if (s > m) m = s;
    }
    return m;
}

ak_result ak_cloth_energy_compute(const ak_cloth* cloth, ak_vec3_cspan positions, ak_vec3_cspan velocities,
                                  ak_vec3 gravity, ak_cloth_energy* out_energy) {
    if (!cloth || !positions.ptr || !velocities.ptr || !out_energy) return AK_ERR_NULL_ARG;
    if (positions.count != cloth->n || velocities.count != cloth->n) return AK_ERR_BAD_ARG;
    ak_cloth_energy e = {0, 0, 0, 0};
    for (size_t v = 0; v < cloth->n; ++v) {
        const double m = cloth->mass[v];
        const ak_vec3 x = positions.ptr[v], u = velocities.ptr[v];
        e.kinetic += 0.5 * m * ((double)u.x * u.x + (double)u.y * u.y + (double)u.z * u.z);
        e.potential -= m * ((double)gravity.x * x.x + (double)gravity.y * x.y + (double)gravity.z * x.z);
    }
    for (size_t k = 0; k < cloth->dist_count; ++k) {
        const akp_dist* c = &cloth->dist[k];
        if (isinf(c->k)) continue;
        const ak_vec3 a = positions.ptr[c->i], b = positions.ptr[c->j];
        const double dx = (double)a.x - b.x, dy = (double)a.y - b.y, dz = (double)a.z - b.z;
        const double C = sqrt(dx * dx + dy * dy + dz * dz) - c->rest;
        e.elastic += 0.5 * c->k * C * C;
    }
    const double kb = cloth->desc.dihedral_stiffness;
    const bool iso = cloth->desc.bending == AK_CLOTH_BEND_ISOMETRIC;
    for (size_t k = 0; k < cloth->bend_count && !isinf(kb); ++k) {
        ak_vec3 x[4];
        for (int q = 0; q < 4; ++q) x[q] = positions.ptr[cloth->bend[k].p[q]];
        if (iso) {
            double b[3] = {0, 0, 0};
            for (int q = 0; q < 4; ++q) {
                if (q == 2) continue;
                b[0] += (double)cloth->bend[k].K[q] * ((double)x[q].x - x[2].x);
                b[1] += (double)cloth->bend[k].K[q] * ((double)x[q].y - x[2].y);
                b[2] += (double)cloth->bend[k].K[q] * ((double)x[q].z - x[2].z);
            }
            const double C = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]) - cloth->bend[k].rest;
            if (cloth->bend[k].alpha > 0.0f) e.elastic += 0.5 * C * C / cloth->bend[k].alpha;
            continue;
        }
        double C = (double)akp_dihedral(x, NULL) - cloth->bend[k].rest;
        if (C > AK_PI) C -= 2.0 * AK_PI;
        if (C < -AK_PI) C += 2.0 * AK_PI;
        e.elastic += 0.5 * kb * C * C;
    }
    e.total = e.kinetic + e.potential + e.elastic;
    *out_energy = e;
    return AK_OK;
}
