/* Boids neighbour search: the naive O(N^2) loop and the grid walk, behind one visit()
 * function, so both paths apply exactly the same tests to exactly the same candidates (the
 * grid only skips agents that are certainly too far). The sums are exact (fixed point), so
 * the order candidates arrive in does not matter; the k-nearest cap keeps the k smallest
 * (distance^2, index) pairs, a strict total order, so it does not depend on order either. */
#include <string.h>

#include "boids_internal.h"
#include "../csort.h"
#include "../simd.h"

/* ---- the per-candidate rules ----------------------------------------------------------- */

static void gather_begin(const akp_boids_ctx* c, size_t i, akp_boids_gather* g) {
    const ak_boids_step_job* job = c->job;
    const uint8_t s = job->species.ptr ? job->species.ptr[i] : 0;
    g->sp = &c->sp[s];
    g->i = (uint32_t)i;
    g->self_k = UINT32_MAX;
    g->species = s;
    g->p = job->positions.ptr[i];
    g->v = job->velocities.ptr[i];
    g->v2 = ak_vec3_length_sq(g->v);
    memset(g->sep, 0, sizeof g->sep);
    memset(g->ali, 0, sizeof g->ali);
    memset(g->coh, 0, sizeof g->coh);
    g->ns = g->na = g->nc = g->nflock = g->kcount = 0;
    g->flee_d2 = g->prey_d2 = INFINITY;
    g->flee_j = g->prey_j = UINT32_MAX;
    g->list = NULL;
    g->list_count = 0;
}

static inline int64_t fix(float x) {
    x = x > -AKP_BOIDS_FIX_CLAMP ? x : -AKP_BOIDS_FIX_CLAMP; /* maxss/minss, no libm call */
    x = x < AKP_BOIDS_FIX_CLAMP ? x : AKP_BOIDS_FIX_CLAMP;
    return (int64_t)x;
}

/* Whether offset d (squared length d2) lies in the view cone of an agent with velocity v
 * (v2 = its squared length). */
static inline bool in_view_v(const akp_boids_sp* S, ak_vec3 v, float v2, float dx, float dy, float dz, float d2) {
    if (S->fov == 0 || v2 == 0.0f || d2 == 0.0f) return true;
    const float dot = dx * v.x + dy * v.y + dz * v.z;
    const float lim = S->cos2 * d2 * v2;
    if (S->fov == 1) return dot > 0.0f && dot * dot >= lim;
    return dot >= 0.0f || dot * dot <= lim;
}

static inline bool in_view(const akp_boids_sp* S, const akp_boids_gather* g, float dx, float dy, float dz,
                           float d2) {
    return in_view_v(S, g->v, g->v2, dx, dy, dz, d2);
}

/* Add one flock neighbour to the rule sums. */
/* qv: the neighbour's velocity in fixed point (fix(v * ali_scale) per component). */
static inline void accumulate(const akp_boids_sp* S, akp_boids_gather* g, float dx, float dy, float dz, float d2,
                              int64_t qvx, int64_t qvy, int64_t qvz) {
    ++g->nflock;
    if (d2 < S->rs2) {
        const float inv = S->sep_scale / (d2 > S->dmin2 ? d2 : S->dmin2);
        g->sep[0] += fix(-dx * inv);
        g->sep[1] += fix(-dy * inv);
        g->sep[2] += fix(-dz * inv);
        ++g->ns;
    }
    if (d2 < S->ra2) {
        g->ali[0] += qvx;
        g->ali[1] += qvy;
        g->ali[2] += qvz;
        ++g->na;
    }
    if (d2 < S->rc2) {
        g->coh[0] += fix(dx * S->coh_scale);
        g->coh[1] += fix(dy * S->coh_scale);
        g->coh[2] += fix(dz * S->coh_scale);
        ++g->nc;
    }
}

static inline bool closer(float d2, uint32_t j, float e2, uint32_t e) { return d2 < e2 || (d2 == e2 && j < e); }

/* Keep the k smallest (d2, j), sorted. */
static inline void keep_nearest(akp_boids_gather* g, uint32_t k, float d2, uint32_t j) {
    uint32_t n = g->kcount;
    if (n == k) {
        if (!closer(d2, j, g->kd2[n - 1], g->kj[n - 1])) return;
        --n;
    }
    while (n > 0 && closer(d2, j, g->kd2[n - 1], g->kj[n - 1])) {
        g->kd2[n] = g->kd2[n - 1];
        g->kj[n] = g->kj[n - 1];
        --n;
    }
    g->kd2[n] = d2;
    g->kj[n] = j;
    ++g->kcount;
    if (g->kcount > k) g->kcount = k;
}

/* One candidate j (position and velocity as stored, species sj). The only place that decides
 * what a neighbour is. */
static inline void visit(akp_boids_gather* g, uint32_t j, float dx, float dy, float dz, float d2, int64_t qvx,
                         int64_t qvy, int64_t qvz, uint8_t sj) {
    const akp_boids_sp* S = g->sp;
    if (j == g->i) return;
    if (sj == g->species && d2 < S->rn2 && in_view(S, g, dx, dy, dz, d2)) {
        if (S->s.k_nearest) keep_nearest(g, S->s.k_nearest, d2, j);
        else {
            if (g->list) g->list[g->list_count++] = j;
            accumulate(S, g, dx, dy, dz, d2, qvx, qvy, qvz);
        }
    }
    const uint32_t bit = 1u << sj;
    if ((S->s.flee_mask & bit) && d2 < S->fr2 && closer(d2, j, g->flee_d2, g->flee_j)) {
        g->flee_d2 = d2;
        g->flee_j = j;
    }
    if ((S->s.pursue_mask & bit) && d2 < S->pr2 && closer(d2, j, g->prey_d2, g->prey_j)) {
        g->prey_d2 = d2;
        g->prey_j = j;
    }
}

/* The k-nearest cap: sum the kept neighbours (from the caller's arrays: the same values the
 * grid copied). */
static void gather_end(const akp_boids_ctx* c, akp_boids_gather* g) {
    const akp_boids_sp* S = g->sp;
    if (!S->s.k_nearest) return;
    const ak_vec3* P = c->job->positions.ptr;
    const ak_vec3* V = c->job->velocities.ptr;
    for (uint32_t a = 0; a < g->kcount; ++a) {
        const uint32_t j = g->kj[a];
        const float dx = P[j].x - g->p.x, dy = P[j].y - g->p.y, dz = P[j].z - g->p.z;
        if (g->list) g->list[g->list_count++] = j;
        accumulate(S, g, dx, dy, dz, g->kd2[a], fix(V[j].x * S->ali_scale), fix(V[j].y * S->ali_scale),
                   fix(V[j].z * S->ali_scale));
    }
}

/* ---- naive path ------------------------------------------------------------------------ */

static void gather_naive(const akp_boids_ctx* c, akp_boids_gather* g) {
    const ak_vec3* P = c->job->positions.ptr;
    const ak_vec3* V = c->job->velocities.ptr;
    const uint8_t* sp = c->job->species.ptr;
    const float q2 = g->sp->query_radius * g->sp->query_radius;
    for (size_t j = 0; j < c->n; ++j) {
        const float dx = P[j].x - g->p.x, dy = P[j].y - g->p.y, dz = P[j].z - g->p.z;
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (!(d2 < q2)) continue;
        const uint8_t sj = sp ? sp[j] : 0;
        const float as = c->sp[sj].ali_scale;
        visit(g, (uint32_t)j, dx, dy, dz, d2, fix(V[j].x * as), fix(V[j].y * as), fix(V[j].z * as), sj);
    }
}

/* ---- grid path -------------------------------------------------------------------------- */

#define MAX_RINGS 4
#define MAX_RANGES ((2 * MAX_RINGS + 1) * (2 * MAX_RINGS + 1) * (2 * MAX_RINGS + 1))

typedef struct cell_ranges {
    uint32_t count;
    uint32_t begin[MAX_RANGES], end[MAX_RANGES];
} cell_ranges;

static void ranges_around(const akp_boids_ctx* c, ak_grid_cell cc, cell_ranges* r) {
    const ak_grid* gr = &c->grid;
    const int R = c->rings;
    r->count = 0;
    for (int dz = -R; dz <= R; ++dz)
        for (int dy = -R; dy <= R; ++dy)
            for (int dx = -R; dx <= R; ++dx) {
                const ak_grid_cell q = {cc.x + dx, cc.y + dy, cc.z + dz};
                const uint32_t m = ak_grid_cell_find(gr, q);
                if (m == UINT32_MAX) continue;
                r->begin[r->count] = gr->cell_start[m];
                r->end[r->count] = gr->cell_start[m + 1];
                ++r->count;
            }
}

static void gather_cells(const akp_boids_ctx* c, const cell_ranges* r, akp_boids_gather* g) {
    const ak_grid* gr = &c->grid;
    const float *X = gr->x, *Y = gr->y, *Z = gr->z;
    const float q2 = g->sp->query_radius * g->sp->query_radius;
    const float px = g->p.x, py = g->p.y, pz = g->p.z;
    for (uint32_t a = 0; a < r->count; ++a) {
        for (uint32_t k = r->begin[a]; k < r->end[a]; ++k) {
            const float dx = X[k] - px, dy = Y[k] - py, dz = Z[k] - pz;
            const float d2 = dx * dx + dy * dy + dz * dz;
            if (!(d2 < q2)) continue;
            visit(g, gr->order[k], dx, dy, dz, d2, c->sqv[3 * k], c->sqv[3 * k + 1], c->sqv[3 * k + 2], c->ssp[k]);
        }
    }
}

/* The candidates of one cell (its neighbour cells' agents) copied into contiguous arrays, so
 * each agent of the cell tests them all in one vectorisable loop, then visits only the hits. */
#define CAND_CAP 1024

typedef struct cand_buf {
    uint32_t count;
    float x[CAND_CAP], y[CAND_CAP], z[CAND_CAP], d2[CAND_CAP];
    uint32_t k[CAND_CAP], j[CAND_CAP], hit[CAND_CAP];
    int64_t qv[3 * CAND_CAP];
    uint8_t sp[CAND_CAP];
} cand_buf;

static bool cand_fill(const akp_boids_ctx* c, const cell_ranges* r, cand_buf* b) {
    const ak_grid* gr = &c->grid;
    uint32_t n = 0;
    for (uint32_t a = 0; a < r->count; ++a) n += r->end[a] - r->begin[a];
    if (n > CAND_CAP) return false;
    n = 0;
    for (uint32_t a = 0; a < r->count; ++a) {
        const uint32_t k0 = r->begin[a], m = r->end[a] - k0;
        /* A few entries per cell: plain loops beat memcpy calls here. */
        for (uint32_t t = 0; t < m; ++t) {
            b->x[n + t] = gr->x[k0 + t];
            b->y[n + t] = gr->y[k0 + t];
            b->z[n + t] = gr->z[k0 + t];
            b->k[n + t] = k0 + t;
            b->j[n + t] = gr->order[k0 + t];
            b->sp[n + t] = c->ssp[k0 + t];
        }
        /* The hits read these: copied here (sequentially), they stay in L1 for the whole cell. */
        for (uint32_t t = 0; t < 3 * m; ++t) b->qv[3 * n + t] = c->sqv[3 * k0 + t];
        n += m;
    }
    b->count = n;
    return true;
}

static void gather_buffered(cand_buf* b, akp_boids_gather* g) {
    const float q2 = g->sp->query_radius * g->sp->query_radius;
    const float px = g->p.x, py = g->p.y, pz = g->p.z;
    const uint32_t n = b->count;
    float* restrict d2 = b->d2;
    const float* restrict X = b->x;
    const float* restrict Y = b->y;
    const float* restrict Z = b->z;
    uint32_t h = 0, t = 0;
#if AK_SIMD_SSE2
    /* Four candidates at a time; the same operations in the same order as the scalar loop
     * (so the same d2 bits), hits appended branch-free from the compare mask. */
    const __m128 vx = _mm_set1_ps(px), vy = _mm_set1_ps(py), vz = _mm_set1_ps(pz), vq = _mm_set1_ps(q2);
    for (; t + 4 <= n; t += 4) {
        const __m128 dx = _mm_sub_ps(_mm_loadu_ps(X + t), vx), dy = _mm_sub_ps(_mm_loadu_ps(Y + t), vy),
                     dz = _mm_sub_ps(_mm_loadu_ps(Z + t), vz);
        const __m128 dd = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        _mm_storeu_ps(d2 + t, dd);
        const unsigned m = (unsigned)_mm_movemask_ps(_mm_cmplt_ps(dd, vq));
        b->hit[h] = t;
        h += m & 1u;
        b->hit[h] = t + 1;
        h += (m >> 1) & 1u;
        b->hit[h] = t + 2;
        h += (m >> 2) & 1u;
        b->hit[h] = t + 3;
        h += (m >> 3) & 1u;
    }
#endif
    for (; t < n; ++t) {
        const float dx = X[t] - px, dy = Y[t] - py, dz = Z[t] - pz;
        d2[t] = dx * dx + dy * dy + dz * dz;
        b->hit[h] = t;
        h += d2[t] < q2;
    }
    const akp_boids_sp* S = g->sp;
    if (S->s.k_nearest || g->list || S->fr2 > 0.0f || S->pr2 > 0.0f) {
        for (uint32_t u = 0; u < h; ++u) {
            const uint32_t t = b->hit[u];
            visit(g, b->j[t], X[t] - px, Y[t] - py, Z[t] - pz, d2[t], b->qv[3 * t], b->qv[3 * t + 1],
                  b->qv[3 * t + 2], b->sp[t]);
        }
        return;
    }
    /* The common case (no cap, no predators, no list): visit() and accumulate() with the sums in
     * registers. Same tests, same values, same integer sums. */
    int64_t s0 = 0, s1 = 0, s2 = 0, a0 = 0, a1 = 0, a2 = 0, c0 = 0, c1 = 0, c2 = 0;
    uint32_t ns = 0, na = 0, nc = 0, nf = 0;
    const uint8_t me = g->species;
    const uint32_t self = g->i;
    for (uint32_t u = 0; u < h; ++u) {
        const uint32_t t = b->hit[u];
        const float dd = d2[t];
        if (b->sp[t] != me || !(dd < S->rn2) || b->j[t] == self) continue;
        const float dx = X[t] - px, dy = Y[t] - py, dz = Z[t] - pz;
        if (!in_view(S, g, dx, dy, dz, dd)) continue;
        ++nf;
        if (dd < S->rs2) {
            const float inv = S->sep_scale / (dd > S->dmin2 ? dd : S->dmin2);
            s0 += fix(-dx * inv);
            s1 += fix(-dy * inv);
            s2 += fix(-dz * inv);
            ++ns;
        }
        if (dd < S->ra2) {
            a0 += b->qv[3 * t];
            a1 += b->qv[3 * t + 1];
            a2 += b->qv[3 * t + 2];
            ++na;
        }
        if (dd < S->rc2) {
            c0 += fix(dx * S->coh_scale);
            c1 += fix(dy * S->coh_scale);
            c2 += fix(dz * S->coh_scale);
            ++nc;
        }
    }
    const int64_t v[9] = {s0, s1, s2, a0, a1, a2, c0, c1, c2};
    akp_boids_gather_add(g, v, ns, na, nc, nf);
}

/* ---- spatial path ------------------------------------------------------------------------ */

/* The rows of a neighbourhood in the spatial layout: (2R+1)^2 contiguous ranges. */
typedef struct row_ranges {
    uint32_t count;
    uint32_t begin[(2 * MAX_RINGS + 1) * (2 * MAX_RINGS + 1)], end[(2 * MAX_RINGS + 1) * (2 * MAX_RINGS + 1)];
} row_ranges;

/* Rows around box cell (x, y, z) (box coordinates). */
static void rows_around(const akp_boids_ctx* c, int64_t x, int64_t y, int64_t z, row_ranges* r) {
    const int R = c->rings;
    const int32_t* dim = c->dense_dim;
    const int64_t xa = x - R > 0 ? x - R : 0, xb = x + R < dim[0] - 1 ? x + R : dim[0] - 1;
    r->count = 0;
    for (int64_t zz = z - R; zz <= z + R; ++zz) {
        if (zz < 0 || zz >= dim[2]) continue;
        for (int64_t yy = y - R; yy <= y + R; ++yy) {
            if (yy < 0 || yy >= dim[1]) continue;
            const size_t row = ((size_t)zz * (size_t)dim[1] + (size_t)yy) * (size_t)dim[0];
            const uint32_t kb = c->dstart[row + (size_t)xa], ke = c->dstart[row + (size_t)xb + 1];
            if (kb == ke) continue;
            r->begin[r->count] = kb;
            r->end[r->count] = ke;
            ++r->count;
        }
    }
}

/* gather_begin from the spatial arrays (the same values, read in order). */
static void gather_begin_spatial(const akp_boids_ctx* c, uint32_t k, akp_boids_gather* g) {
    const uint8_t s = c->ssp[k];
    g->sp = &c->sp[s];
    g->i = c->sj[k];
    g->self_k = k;
    g->species = s;
    g->p = ak_vec3_make(c->sx[k], c->sy[k], c->sz[k]);
    g->v = c->sv[k];
    g->v2 = ak_vec3_length_sq(g->v);
    memset(g->sep, 0, sizeof g->sep);
    memset(g->ali, 0, sizeof g->ali);
    memset(g->coh, 0, sizeof g->coh);
    g->ns = g->na = g->nc = g->nflock = g->kcount = 0;
    g->flee_d2 = g->prey_d2 = INFINITY;
    g->flee_j = g->prey_j = UINT32_MAX;
    g->list = NULL;
    g->list_count = 0;
}

/* Hits held before they are visited (a bound on the stack, not on the candidates). */
#define HIT_CAP AKP_BOIDS_HIT_CAP
#define HIT_PIECE 128

/* Visit the hits hk[0..h) (spatial indices, with their d2). */
static void visit_hits(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* hb, uint32_t h) {
    const uint32_t* hk = hb->k;
    const float* hd = hb->d2;
    const float *X = c->sx, *Y = c->sy, *Z = c->sz;
    const int64_t* qv = c->sqv;
    const float px = g->p.x, py = g->p.y, pz = g->p.z;
    const akp_boids_sp* S = g->sp;
    if (S->s.k_nearest || g->list || S->fr2 > 0.0f || S->pr2 > 0.0f) {
        for (uint32_t u = 0; u < h; ++u) {
            const uint32_t t = hk[u];
            visit(g, c->sj[t], X[t] - px, Y[t] - py, Z[t] - pz, hd[u], qv[3 * t], qv[3 * t + 1], qv[3 * t + 2],
                  c->ssp[t]);
        }
        return;
    }
    /* The common case (no cap, no predators, no list): visit() and accumulate() with the sums in
     * registers. Same tests, same values, same integer sums. */
    if (c->avx512 && c->one_species) {
        akp_boids_visit_avx512(c, g, hb, h);
        return;
    }
    int64_t s0 = 0, s1 = 0, s2 = 0, a0 = 0, a1 = 0, a2 = 0, c0 = 0, c1 = 0, c2 = 0;
    uint32_t ns = 0, na = 0, nc = 0, nf = 0;
    const uint8_t me = g->species;
    const uint32_t self = g->i;
    for (uint32_t u = 0; u < h; ++u) {
        const uint32_t t = hk[u];
        const float dd = hd[u];
        if (c->ssp[t] != me || !(dd < S->rn2) || c->sj[t] == self) continue;
        const float dx = X[t] - px, dy = Y[t] - py, dz = Z[t] - pz;
        if (!in_view(S, g, dx, dy, dz, dd)) continue;
        ++nf;
        if (dd < S->rs2) {
            const float inv = S->sep_scale / (dd > S->dmin2 ? dd : S->dmin2);
            s0 += fix(-dx * inv);
            s1 += fix(-dy * inv);
            s2 += fix(-dz * inv);
            ++ns;
        }
        if (dd < S->ra2) {
            a0 += qv[3 * t];
            a1 += qv[3 * t + 1];
            a2 += qv[3 * t + 2];
            ++na;
        }
        if (dd < S->rc2) {
            c0 += fix(dx * S->coh_scale);
            c1 += fix(dy * S->coh_scale);
            c2 += fix(dz * S->coh_scale);
            ++nc;
        }
    }
    const int64_t v[9] = {s0, s1, s2, a0, a1, a2, c0, c1, c2};
    akp_boids_gather_add(g, v, ns, na, nc, nf);
}

/* The candidates of the rows straight from the spatial arrays: distances (the same operations
 * as everywhere, so the same d2 bits), hits appended branch-free, visited in batches. */
static void gather_rows(const akp_boids_ctx* c, const row_ranges* r, akp_boids_gather* g) {
    const float q2 = g->sp->query_radius * g->sp->query_radius;
    const float px = g->p.x, py = g->p.y, pz = g->p.z;
    const float* restrict X = c->sx;
    const float* restrict Y = c->sy;
    const float* restrict Z = c->sz;
    akp_boids_hits hb;
    uint32_t h = 0;
    if (c->avx512) {
        /* Rows in pieces of at most HIT_PIECE, so a piece's hits (+16 stored past them) fit. */
        for (uint32_t a = 0; a < r->count; ++a)
            for (uint32_t t = r->begin[a]; t < r->end[a]; t += HIT_PIECE) {
                const uint32_t e = r->end[a] - t > HIT_PIECE ? t + HIT_PIECE : r->end[a];
                if (h + HIT_PIECE + 16 > HIT_CAP) {
                    visit_hits(c, g, &hb, h);
                    h = 0;
                }
                h += akp_boids_filter_avx512(X, Y, Z, t, e, g->p, q2, &hb, h);
            }
        visit_hits(c, g, &hb, h);
        return;
    }
#if AK_SIMD_SSE2
    const __m128 vx = _mm_set1_ps(px), vy = _mm_set1_ps(py), vz = _mm_set1_ps(pz), vq = _mm_set1_ps(q2);
#endif
    for (uint32_t a = 0; a < r->count; ++a) {
        uint32_t t = r->begin[a];
        const uint32_t e = r->end[a];
#if AK_SIMD_SSE2
        for (; t + 4 <= e; t += 4) {
            const __m128 dx = _mm_sub_ps(_mm_loadu_ps(X + t), vx), dy = _mm_sub_ps(_mm_loadu_ps(Y + t), vy),
                         dz = _mm_sub_ps(_mm_loadu_ps(Z + t), vz);
            const __m128 dd = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            const unsigned m = (unsigned)_mm_movemask_ps(_mm_cmplt_ps(dd, vq));
            if (!m) continue;
            float d4[4];
            _mm_storeu_ps(d4, dd);
            for (unsigned l = 0; l < 4; ++l) {
                hb.k[h] = t + l;
                hb.d2[h] = d4[l];
                h += (m >> l) & 1u;
            }
            if (h > HIT_CAP - 4) {
                visit_hits(c, g, &hb, h);
                h = 0;
            }
        }
#endif
        for (; t < e; ++t) {
            const float dx = X[t] - px, dy = Y[t] - py, dz = Z[t] - pz;
            const float dd = dx * dx + dy * dy + dz * dz;
            hb.k[h] = t;
            hb.d2[h] = dd;
            h += dd < q2;
            if (h > HIT_CAP - 4) {
                visit_hits(c, g, &hb, h);
                h = 0;
            }
        }
    }
    visit_hits(c, g, &hb, h);
}

/* ---- symmetric pair pass ---------------------------------------------------------------- */

/* The distance test for every pair (i, j) with d2 < q2 runs once, from the agent that comes
 * first in the (z, y, x) cell order (in the same cell: the lower spatial index), over the
 * forward half of its neighbourhood: the rest of its own cell and the next cell of its row,
 * the three cells of the next row, the nine of the next slab. Each direction then applies its
 * own tests (view cone with its own velocity; the radii are symmetric) to the same values:
 * j - i is exactly -(i - j) in floats, fix() is odd, so what j receives from the pair is
 * bit for bit what j's own walk over its neighbourhood would have summed. Every agent's sums
 * are complete once the agents before it are done, so integration follows at once; only the
 * first rows of each part after the first wait (its deferred rows: the dim[1] + 1 rows that
 * the part before reaches): their agents also receive from the rows before, on the other
 * thread, which credits them in a spill buffer (or, when the deferred rows hold more agents
 * than it has room for, by atomic adds); they integrate after both are done. The parts are
 * runs of whole rows of about equal estimated work (akp_boids_partition). Integer sums: the
 * same bits in any order, so the partition does not change them. */

/* Agent g against its forward hits [0, h): g's sums in g, the hits' credits in c->acc. */
static void sym_hits(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* hb, uint32_t h,
                     const akp_boids_sink* sink) {
    if (c->avx512) {
        akp_boids_sym_avx512(c, g, hb, h, sink);
        return;
    }
    if (c->avx2) {
        akp_boids_sym_avx2(c, g, hb, h, sink);
        return;
    }
    const akp_boids_sp* S = g->sp;
    const float *X = c->sx, *Y = c->sy, *Z = c->sz;
    const int64_t* qv = c->sqv;
    const int64_t* qi = qv + 3 * (size_t)g->self_k;
    const float px = g->p.x, py = g->p.y, pz = g->p.z;
    const bool cone = S->fov != 0;
    int64_t s0 = 0, s1 = 0, s2 = 0, a0 = 0, a1 = 0, a2 = 0, c0 = 0, c1 = 0, c2 = 0;
    uint32_t ns = 0, na = 0, nc = 0, nf = 0;
    for (uint32_t u = 0; u < h; ++u) {
        const uint32_t t = hb->k[u];
        const float dd = hb->d2[u];
        if (!(dd < S->rn2)) continue;
        const float dx = X[t] - px, dy = Y[t] - py, dz = Z[t] - pz;
        bool see_i = true, see_j = true;
        if (cone) { /* (no read of the partner's velocity without one) */
            see_i = in_view(S, g, dx, dy, dz, dd);
            const ak_vec3 vj = c->sv[t];
            see_j = in_view_v(S, vj, ak_vec3_length_sq(vj), -dx, -dy, -dz, dd);
            if (!see_i && !see_j) continue;
        }
        const bool bs = dd < S->rs2, ba = dd < S->ra2, bc = dd < S->rc2;
        int64_t e[3] = {0, 0, 0}, f[3] = {0, 0, 0};
        if (bs) {
            const float inv = S->sep_scale / (dd > S->dmin2 ? dd : S->dmin2);
            e[0] = fix(-dx * inv);
            e[1] = fix(-dy * inv);
            e[2] = fix(-dz * inv);
        }
        if (bc) {
            f[0] = fix(dx * S->coh_scale);
            f[1] = fix(dy * S->coh_scale);
            f[2] = fix(dz * S->coh_scale);
        }
        if (see_i) {
            ++nf;
            s0 += e[0], s1 += e[1], s2 += e[2], ns += bs;
            c0 += f[0], c1 += f[1], c2 += f[2], nc += bc;
            if (ba) a0 += qv[3 * t], a1 += qv[3 * t + 1], a2 += qv[3 * t + 2], ++na;
        }
        if (see_j) {
            const int64_t v[9] = {-e[0], -e[1], -e[2], ba ? qi[0] : 0, ba ? qi[1] : 0, ba ? qi[2] : 0,
                                  -f[0], -f[1], -f[2]};
            const uint64_t n01 = (uint64_t)bs | (uint64_t)ba << 32, n23 = (uint64_t)bc | (uint64_t)1 << 32;
            if (t >= sink->far_begin && sink->spill)
                akp_boids_credit(&sink->spill[t - sink->far_begin], v, n01, n23, false);
            else
                akp_boids_credit(&sink->acc[t], v, n01, n23, t < sink->atomic_end || t >= sink->far_begin);
        }
    }
    const int64_t v[9] = {s0, s1, s2, a0, a1, a2, c0, c1, c2};
    akp_boids_gather_add(g, v, ns, na, nc, nf);
}

/* The distance filter of the scalar/SSE2 path: appends the t in [begin, end) with d2 < q2 (k
 * and d2, and the offsets when `offsets`: the AVX2 pair kernel reads them, the scalar one
 * recomputes them) to h at `at`; returns how many (h needs room for end - begin more). */
static uint32_t filter_sse2(const float* restrict X, const float* restrict Y, const float* restrict Z,
                            uint32_t begin, uint32_t end, ak_vec3 p, float q2, bool offsets, akp_boids_hits* hb,
                            uint32_t at) {
    uint32_t h = at, t = begin;
#if AK_SIMD_SSE2
    const __m128 vx = _mm_set1_ps(p.x), vy = _mm_set1_ps(p.y), vz = _mm_set1_ps(p.z), vq = _mm_set1_ps(q2);
    for (; t + 4 <= end; t += 4) {
        const __m128 dx = _mm_sub_ps(_mm_loadu_ps(X + t), vx), dy = _mm_sub_ps(_mm_loadu_ps(Y + t), vy),
                     dz = _mm_sub_ps(_mm_loadu_ps(Z + t), vz);
        const __m128 dd = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        const unsigned m = (unsigned)_mm_movemask_ps(_mm_cmplt_ps(dd, vq));
        /* No branch on m: whether a group of 4 hits is a coin toss (about half of them do at
         * the usual density), and a mispredicted branch costs more than the 4 stores. */
        float d4[4], x4[4], y4[4], z4[4];
        _mm_storeu_ps(d4, dd);
        _mm_storeu_ps(x4, dx);
        _mm_storeu_ps(y4, dy);
        _mm_storeu_ps(z4, dz);
        for (unsigned l = 0; l < 4; ++l) {
            hb->k[h] = t + l;
            hb->d2[h] = d4[l];
            if (offsets) {
                hb->dx[h] = x4[l];
                hb->dy[h] = y4[l];
                hb->dz[h] = z4[l];
            }
            h += (m >> l) & 1u;
        }
    }
#endif
    for (; t < end; ++t) {
        const float dx = X[t] - p.x, dy = Y[t] - p.y, dz = Z[t] - p.z;
        const float dd = dx * dx + dy * dy + dz * dz;
        hb->k[h] = t;
        hb->d2[h] = dd;
        if (offsets) {
            hb->dx[h] = dx;
            hb->dy[h] = dy;
            hb->dz[h] = dz;
        }
        h += dd < q2;
    }
    return h - at;
}

/* Spatial index of the first agent of row r of the dense box (r <= dim[1] dim[2]). */
static uint32_t row_start(const akp_boids_ctx* c, size_t r) { return c->dstart[r * (size_t)c->dense_dim[0]]; }

static void acc_zero_rows(const akp_boids_ctx* c, size_t r0, size_t r1) {
    const uint32_t b = row_start(c, r0), e = row_start(c, r1);
    memset(c->acc + b, 0, (size_t)(e - b) * sizeof(akp_boids_acc));
}

/* A row's estimated work, in units of a candidate's distance test times 2 dim[0]: its agents
 * times (a fixed cost per agent, ROW_AGENT_COST tests, plus the candidates of the forward
 * rows of the symmetric pass: 3 cells of each of them, a cell and a half of its own row). */
#define ROW_AGENT_COST 32u
static uint64_t row_work(const akp_boids_ctx* c, size_t r) {
    const size_t dimy = (size_t)c->dense_dim[1], dimz = (size_t)c->dense_dim[2], y = r % dimy, z = r / dimy;
    const uint64_t k = row_start(c, r + 1) - row_start(c, r);
    if (!k) return 0;
    uint64_t f2 = k; /* twice the forward rows' agents, the own row counted half */
    if (y + 1 < dimy) f2 += 2u * (row_start(c, r + 2) - row_start(c, r + 1));
    if (z + 1 < dimz) {
        const size_t a = y > 0 ? r + dimy - 1 : r + dimy, b = y + 1 < dimy ? r + dimy + 2 : r + dimy + 1;
        f2 += 2u * (uint64_t)(row_start(c, b) - row_start(c, a));
    }
    return k * (2u * ROW_AGENT_COST * (uint64_t)c->dense_dim[0] + 3u * f2);
}

void akp_boids_partition(akp_boids_ctx* c, size_t parts) {
    if (parts < 1) parts = 1;
    if (parts > 64) parts = 64;
    if (c->dstart && c->part_count == parts) return; /* made by akp_boids_search_prepare */
    c->part_count = 0;
    if (!c->dstart) return;
    const size_t dimy = (size_t)c->dense_dim[1], rows = dimy * (size_t)c->dense_dim[2];
    const size_t min_rows = c->sym ? dimy + 1 : 1;
    size_t use = rows / min_rows < parts ? rows / min_rows : parts;
    if (use < 1) use = 1;
    uint64_t total = 0;
    for (size_t r = 0; r < rows; ++r) total += row_work(c, r);
    /* Part p starts at the first row whose work before it reaches p / use of the total
     * (walked once), kept min_rows after the part before and min_rows per part to come
     * before the end. */
    c->part_row[0] = 0;
    uint64_t done = 0;
    size_t r = 0;
    for (size_t p = 1; p < use; ++p) {
        const uint64_t target = total / use * p + total % use * p / use;
        while (r < rows && done < target) done += row_work(c, r++);
        size_t b = r;
        if (b < c->part_row[p - 1] + min_rows) b = c->part_row[p - 1] + min_rows;
        if (b > rows - (use - p) * min_rows) b = rows - (use - p) * min_rows;
        c->part_row[p] = (uint32_t)b;
    }
    for (size_t p = use; p <= parts; ++p) c->part_row[p] = (uint32_t)rows;
    /* A row's forward rows reach dim[1] + 1 rows ahead: the rows part p - 1 credits. */
    c->defer_row[0] = 0;
    for (size_t p = 1; p < parts; ++p) {
        const size_t b = c->part_row[p], reach = b + dimy + 1;
        c->defer_row[p] = (uint32_t)(!c->sym ? b : reach < c->part_row[p + 1] ? reach : c->part_row[p + 1]);
    }
    c->part_count = (uint32_t)parts;
}

/* Agents of part p's deferred rows (none for p = 0 and empty parts). */
static size_t deferred_count(const akp_boids_ctx* c, size_t p) {
    return row_start(c, c->defer_row[p]) - row_start(c, c->part_row[p]);
}

/* First spill entry of part p's deferred rows: those of parts 1 .. p - 1, side by side. */
static size_t spill_base(const akp_boids_ctx* c, size_t p) {
    size_t base = 0;
    for (size_t t = 1; t < p; ++t) base += deferred_count(c, t);
    return base;
}

/* Whether the deferred rows' credits go to spill (they fit it) or to acc by atomic adds. */
static void sym_plan(akp_boids_ctx* c, size_t parts) { c->use_spill = spill_base(c, parts) <= c->spill_cap; }

/* Part `part` of `parts` of the zeroing of the deferred rows' sums (spill entries, or the
 * rows' acc entries), taken in order as in spill: for the fill's threads, so the caller does
 * not zero them between sections (about 28 MB at 16 threads of a 1M step). */
static void sym_zero_share(const akp_boids_ctx* c, size_t part, size_t parts) {
    const size_t total = spill_base(c, c->part_count);
    const size_t m0 = total * part / parts, m1 = total * (part + 1) / parts;
    if (c->use_spill) {
        memset(c->spill + m0, 0, (m1 - m0) * sizeof(akp_boids_acc));
        return;
    }
    size_t base = 0;
    for (size_t t = 1; t < c->part_count && base < m1; ++t) {
        const uint32_t b = row_start(c, c->part_row[t]), e = row_start(c, c->defer_row[t]);
        const size_t from = m0 > base ? m0 - base : 0, to = m1 - base < e - b ? m1 - base : e - b;
        if (from < to) memset(c->acc + b + from, 0, (to - from) * sizeof(akp_boids_acc));
        base += e - b;
    }
}

void akp_boids_sym_clear(akp_boids_ctx* c, size_t parts) {
    if (c->part_count != parts) {
        akp_boids_partition(c, parts);
        c->sym_zeroed = false;
    }
    if (c->sym_zeroed) return; /* sym_plan and the zeroing ran in the fill */
    const size_t need = spill_base(c, parts);
    sym_plan(c, parts);
    if (c->use_spill) {
        memset(c->spill, 0, need * sizeof(akp_boids_acc));
        return;
    }
    for (size_t t = 1; t < parts; ++t) acc_zero_rows(c, c->part_row[t], c->defer_row[t]);
}

/* What the agent received, added to its own sums. */
static void add_received(const akp_boids_acc* A, akp_boids_gather* g) {
    const int64_t v[9] = {A->sep[0], A->sep[1], A->sep[2], A->ali[0], A->ali[1], A->ali[2], A->coh[0], A->coh[1], A->coh[2]};
    akp_boids_gather_add(g, v, (uint32_t)A->n01, (uint32_t)(A->n01 >> 32), (uint32_t)A->n23, (uint32_t)(A->n23 >> 32));
}

void akp_boids_sym_range(const akp_boids_ctx* c, size_t part, size_t parts, akp_boids_agent_fn fn, void* user) {
    (void)parts; /* c->part_row was made for them (akp_boids_sym_clear) */
    const size_t r0 = c->part_row[part], r1 = c->part_row[part + 1];
    if (r0 == r1) return;
    const int64_t dimx = c->dense_dim[0], dimy = c->dense_dim[1], dimz = c->dense_dim[2];
    const size_t rows = (size_t)dimy * (size_t)dimz;
    const uint32_t* ds = c->dstart;
    /* The deferred rows wait: the part before credits them too. */
    const uint32_t first_end = part > 0 ? row_start(c, c->defer_row[part]) : 0;
    akp_boids_sink sink = {c->acc, NULL, c->use_spill ? 0 : first_end, row_start(c, r1)};
    if (c->use_spill && r1 < rows) sink.spill = c->spill + spill_base(c, part + 1);
    const float q2 = c->sp[0].query_radius * c->sp[0].query_radius;
    const float *X = c->sx, *Y = c->sy, *Z = c->sz;
    akp_boids_gather g;
    akp_boids_hits hb;
    akp_boids_packed pkv; /* 6 KiB */
    akp_boids_packed* pk = &pkv;
    /* acc is zeroed a little ahead of the rows that credit it (dim[1] + 1 rows ahead of the
     * current one); the deferred rows' by akp_boids_sym_clear unless spill takes the part
     * before's credits. */
    size_t zeroed = part == 0 || c->use_spill ? r0 : c->defer_row[part];
    for (size_t rw = r0; rw < r1; ++rw) {
        const size_t ahead = rw + (size_t)dimy + 2 < r1 ? rw + (size_t)dimy + 2 : r1;
        if (zeroed < ahead) {
            acc_zero_rows(c, zeroed, ahead);
            zeroed = ahead;
        }
        const int64_t z = (int64_t)(rw / (size_t)dimy), y = (int64_t)(rw % (size_t)dimy);
        {
            const size_t row = rw * (size_t)dimx;
            for (int64_t x = 0; x < dimx; ++x) {
                const uint32_t k0 = ds[row + (size_t)x], k1 = ds[row + (size_t)x + 1];
                if (k0 == k1) continue;
                /* The forward rows: [0] the rest of this row up to x + 1 (its begin is per
                 * agent), then (z, y + 1) and (z + 1, y - 1 .. y + 1), each x - 1 .. x + 1. */
                uint32_t rb[5], re[5], nr = 1;
                const int64_t xa = x > 0 ? x - 1 : 0, xb = x + 1 < dimx ? x + 1 : dimx - 1;
                re[0] = ds[row + (size_t)xb + 1];
                rb[0] = 0;
                for (int r = 0; r < 4; ++r) {
                    const int64_t zz = r == 0 ? z : z + 1, yy = r == 0 ? y + 1 : y + r - 2;
                    if (zz >= dimz || yy < 0 || yy >= dimy) continue;
                    const size_t rr = ((size_t)zz * (size_t)dimy + (size_t)yy) * (size_t)dimx;
                    rb[nr] = ds[rr + (size_t)xa];
                    re[nr] = ds[rr + (size_t)xb + 1];
                    if (rb[nr] < re[nr]) ++nr;
                }
                uint32_t span = 0; /* candidates of the forward rows (row 0 from k0 + 1) */
                for (uint32_t a = 1; a < nr; ++a) span += re[a] - rb[a];
                span += re[0] - k0;
                /* Several agents share the cell's candidates: pack them once (all but the
                 * cell's own, which each agent takes from k + 1). */
                uint32_t packed = 0;
                const bool pack = (c->avx512 || c->avx2) && k1 - k0 > 1 && span + 32 <= HIT_CAP &&
                                  span - (k1 - k0 - 1) <= AKP_BOIDS_PACK_CAP;
                if (pack) {
                    rb[0] = k1;
                    packed = c->avx512 ? akp_boids_pack_rows_avx512(X, Y, Z, rb, re, nr, pk)
                                       : akp_boids_pack_rows_avx2(X, Y, Z, rb, re, nr, pk);
                }
                for (uint32_t k = k0; k < k1; ++k) {
                    gather_begin_spatial(c, k, &g);
                    rb[0] = k + 1;
                    uint32_t h = 0;
                    if (pack && c->avx512)
                        h = akp_boids_filter_packed_avx512(X, Y, Z, k + 1, k1, pk, packed, g.p, q2, &hb, 0);
                    else if (pack)
                        h = akp_boids_filter_packed_avx2(X, Y, Z, k + 1, k1, pk, packed, g.p, q2, &hb, 0);
                    else if (c->avx512 && span + 16 <= HIT_CAP) /* all rows in one call */
                        h = akp_boids_filter_rows_avx512(X, Y, Z, rb, re, nr, g.p, q2, &hb, 0);
                    else if (c->avx2 && span + 16 <= HIT_CAP)
                        h = akp_boids_filter_rows_avx2(X, Y, Z, rb, re, nr, g.p, q2, &hb, 0);
                    else
                        for (uint32_t a = 0; a < nr; ++a)
                            for (uint32_t t = rb[a]; t < re[a]; t += HIT_PIECE) {
                                const uint32_t e = re[a] - t > HIT_PIECE ? t + HIT_PIECE : re[a];
                                if (h + HIT_PIECE + 16 > HIT_CAP) {
                                    sym_hits(c, &g, &hb, h, &sink);
                                    h = 0;
                                }
                                h += c->avx512 ? akp_boids_filter_avx512(X, Y, Z, t, e, g.p, q2, &hb, h)
                                               : filter_sse2(X, Y, Z, t, e, g.p, q2, c->avx2, &hb, h);
                            }
                    sym_hits(c, &g, &hb, h, &sink);
                    if (k < first_end) {
                        /* A deferred row: the part before credits it too. */
                        const int64_t v[9] = {g.sep[0], g.sep[1], g.sep[2], g.ali[0], g.ali[1],
                                              g.ali[2], g.coh[0], g.coh[1], g.coh[2]};
                        akp_boids_credit(&c->acc[k], v, (uint64_t)g.ns | (uint64_t)g.na << 32,
                               (uint64_t)g.nc | (uint64_t)g.nflock << 32, !c->use_spill);
                        continue;
                    }
                    add_received(&c->acc[k], &g);
                    fn(c, g.i, &g, user);
                }
            }
        }
    }
}

void akp_boids_sym_finish(const akp_boids_ctx* c, size_t part, size_t parts, akp_boids_agent_fn fn, void* user) {
    /* The deferred agents (the deferred rows of the parts after the first, in order, as in
     * spill) split evenly over the parts. */
    const size_t total = spill_base(c, parts);
    const size_t mine0 = total * part / parts, mine1 = total * (part + 1) / parts;
    akp_boids_gather g;
    size_t base = 0;
    for (size_t t = 1; t < parts && base < mine1; ++t) {
        const uint32_t b = row_start(c, c->part_row[t]), e = row_start(c, c->defer_row[t]);
        if (b == e) continue;
        const akp_boids_acc* spill = c->use_spill ? c->spill + base : NULL;
        /* This part's deferred positions [base, base + e - b) against [mine0, mine1). */
        const size_t from = mine0 > base ? mine0 - base : 0, to = mine1 - base < e - b ? mine1 - base : e - b;
        for (size_t d = from; d < to; ++d) {
            const uint32_t k = b + (uint32_t)d;
            gather_begin_spatial(c, k, &g);
            add_received(&c->acc[k], &g);
            if (spill) add_received(&spill[d], &g);
            fn(c, g.i, &g, user);
        }
        base += e - b;
    }
}

/* Box coordinates of p's cell (p is an agent of the step, so its cell is in the box). */
static void box_cell(const akp_boids_ctx* c, ak_vec3 p, int64_t* x, int64_t* y, int64_t* z) {
    const ak_grid_cell q = ak_grid_cell_of(&c->grid, p);
    *x = (int64_t)q.x - c->dense_min[0];
    *y = (int64_t)q.y - c->dense_min[1];
    *z = (int64_t)q.z - c->dense_min[2];
}

/* ---- scratch ----------------------------------------------------------------------------- */

/* Cell size: the largest flock radius (most agents' queries then visit 27 cells); species
 * that look farther (flee, pursue) visit more rings, at most MAX_RINGS. */
static float cell_size_for(const ak_boids_params* p, float* out_search) {
    float flock = 0.0f, query = 0.0f;
    for (uint32_t s = 0; s < p->species_count; ++s) {
        ak_boids_species r;
        ak_boids_species_resolved(&p->species[s], &r);
        const float rs = r.separation_weight > 0.0f ? r.separation_radius : 0.0f;
        const float ra = r.alignment_weight > 0.0f ? r.alignment_radius : 0.0f;
        const float rc = r.cohesion_weight > 0.0f ? r.cohesion_radius : 0.0f;
        const float fr = (r.flee_mask && r.flee_weight > 0.0f) ? r.flee_radius : 0.0f;
        const float pr = (r.pursue_mask && r.pursue_weight > 0.0f) ? r.pursue_radius : 0.0f;
        flock = ak_maxf(flock, ak_maxf(rs, ak_maxf(ra, rc)));
        query = ak_maxf(query, ak_maxf(ak_maxf(rs, ak_maxf(ra, rc)), ak_maxf(fr, pr)));
    }
    if (out_search) *out_search = query;
    if (query <= 0.0f) return 0.0f;
    float cs = flock > 0.0f ? flock : query;
    if (query > cs * MAX_RINGS) cs = query / MAX_RINGS;
    return cs;
}

static size_t align64(size_t n) { return (n + 63u) & ~(size_t)63u; }

/* Entries of the dense cell table (4 per agent: a flock fills a fair part of its box). */
static size_t dense_cap(size_t n) { return 4 * n + 4096; }

/* Whether the step can take the symmetric pair pass (see akp_boids_sym_range): one species
 * that only flocks (no k cap, no flee or pursue), so neighbour sums are the only thing a
 * pair contributes, and each pair can be found once and credited in both directions. */
static bool sym_params(const ak_boids_params* p) {
    if (p->species_count != 1) return false;
    ak_boids_species s;
    ak_boids_species_resolved(&p->species[0], &s);
    return s.k_nearest == 0 && !((s.flee_mask & 1u) && s.flee_weight > 0.0f) &&
           !((s.pursue_mask & 1u) && s.pursue_weight > 0.0f);
}

size_t akp_boids_search_scratch_size(const ak_boids_step_job* job) {
    float search;
    const float cs = cell_size_for(job->params, &search);
    if (cs <= 0.0f || !ak_finitef(cs)) return 0;
    const size_t n = job->positions.count;
    const ak_grid_desc gd = {.cell_size = cs};
    const size_t g = ak_grid_memory_size(n, &gd);
    if (g == 0) return 0;
    const size_t acc = sym_params(job->params) ? align64(n * sizeof(akp_boids_acc)) : 0;
    return align64(g) + align64(3 * n * sizeof(int64_t)) + align64(n) + align64((dense_cap(n) + 1) * sizeof(uint32_t)) +
           3 * align64(n * sizeof(float)) + align64(n * sizeof(ak_vec3)) + align64(n * sizeof(uint32_t)) + acc + 64;
}

/* The grid's cell coordinate (ak_grid_cell_of: floor(p / cell_size) in double, clamped to
 * +-2^30), with the floor as a truncation and a step down (the same integer, no libm call). */
static inline int32_t cell_axis(float p, double inv) {
    const double v = (double)p * inv;
    if (!(v >= -1073741824.0)) return -1073741824;
    if (v > 1073741824.0) return 1073741824;
    const int32_t t = (int32_t)v;
    return (double)t > v ? t - 1 : t;
}

/* The cells of agents [n part / parts, n (part + 1) / parts) and their bounds. */
typedef struct cells_task {
    const akp_boids_ctx* c;
    int32_t* cells;
    size_t part, parts;
    int32_t lo[3], hi[3];
} cells_task;

static void* cells_thread(void* arg) {
    cells_task* t = (cells_task*)arg;
    const ak_vec3* P = t->c->job->positions.ptr;
    const double inv = 1.0 / (double)t->c->grid.cell_size;
    const size_t b = t->c->n * t->part / t->parts, e = t->c->n * (t->part + 1) / t->parts;
    int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    int32_t* cells = t->cells;
    for (size_t i = b; i < e; ++i) {
        const int32_t q[3] = {cell_axis(P[i].x, inv), cell_axis(P[i].y, inv), cell_axis(P[i].z, inv)};
        for (int a = 0; a < 3; ++a) {
            cells[3 * i + (size_t)a] = q[a];
            lo[a] = q[a] < lo[a] ? q[a] : lo[a];
            hi[a] = q[a] > hi[a] ? q[a] : hi[a];
        }
    }
    memcpy(t->lo, lo, sizeof lo);
    memcpy(t->hi, hi, sizeof hi);
    return NULL;
}

/* The spatial layout straight from the positions, without the hashed grid: the box of the
 * occupied cells (the cells found over threads for large steps), then a counting sort by box
 * cell, stable (agents of a cell in increasing index, the order the grid gives its cells).
 * cells: [3n] temporary. False when the box does not fit dense_cap (the caller builds the
 * grid). */
static bool dense_direct(akp_boids_ctx* c, int32_t* cells) {
    const size_t n = c->n;
    uint32_t parts = akp_boids_threads(c->job->thread_count, n);
    if (n < 2048) parts = 1; /* as the fill below: smaller steps are not worth a thread */
    cells_task tasks[64];
    for (uint32_t t = 0; t < parts; ++t) tasks[t] = (cells_task){.c = c, .cells = cells, .part = t, .parts = parts};
    if (parts == 1) cells_thread(&tasks[0]);
    else akp_boids_run_tasks(cells_thread, tasks, sizeof tasks[0], parts);
    int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    for (uint32_t t = 0; t < parts; ++t)
        for (int a = 0; a < 3; ++a) {
            lo[a] = tasks[t].lo[a] < lo[a] ? tasks[t].lo[a] : lo[a];
            hi[a] = tasks[t].hi[a] > hi[a] ? tasks[t].hi[a] : hi[a];
        }
    const int64_t dx = (int64_t)hi[0] - lo[0] + 1, dy = (int64_t)hi[1] - lo[1] + 1, dz = (int64_t)hi[2] - lo[2] + 1;
    const size_t cap = dense_cap(n);
    if (n == 0 || dx > (int64_t)cap || dy > (int64_t)cap || dz > (int64_t)cap || dx * dy > (int64_t)cap ||
        dx * dy * dz > (int64_t)cap)
        return false;
    for (int a = 0; a < 3; ++a) c->dense_min[a] = lo[a];
    c->dense_dim[0] = (int32_t)dx;
    c->dense_dim[1] = (int32_t)dy;
    c->dense_dim[2] = (int32_t)dz;
    return true;
}

void akp_boids_search_fill(const akp_boids_ctx* c, size_t part, size_t parts) {
    const size_t b = c->n * part / parts, e = c->n * (part + 1) / parts;
    const ak_vec3* P = c->job->positions.ptr;
    const ak_vec3* V = c->job->velocities.ptr;
    const uint8_t* S = c->job->species.ptr;
    for (size_t d = b; d < e; ++d) {
        if (d + 16 < e) { /* the reads through sj are scattered: fetch ahead */
            __builtin_prefetch(&P[c->sj[d + 16]]);
            __builtin_prefetch(&V[c->sj[d + 16]]);
        }
        const uint32_t i = c->sj[d];
        const uint8_t s = S ? S[i] : 0;
        const float as = c->sp[s].ali_scale;
        const ak_vec3 v = V[i];
        c->fill_sx[d] = P[i].x;
        c->fill_sy[d] = P[i].y;
        c->fill_sz[d] = P[i].z;
        c->fill_sv[d] = v;
        c->fill_sp[d] = s;
        c->fill_qv[3 * d] = fix(v.x * as);
        c->fill_qv[3 * d + 1] = fix(v.y * as);
        c->fill_qv[3 * d + 2] = fix(v.z * as);
    }
}

static void* fill_thread(void* arg) {
    const akp_boids_fill_task* t = (const akp_boids_fill_task*)arg;
    akp_boids_search_fill(t->c, t->part, t->parts);
    if (t->c->sym && t->c->part_count == t->parts) sym_zero_share(t->c, t->part, t->parts);
    return NULL;
}

/* The dense layout's parts (akp_boids_search_prepare): agents [n part / parts, n (part + 1) /
 * parts) for the box indices, cells [volume part / parts, ...) for the load. */
typedef struct box_task {
    const akp_boids_ctx* c;
    const int32_t* cells;
    uint32_t* keys;
    const uint32_t* start;
    size_t volume;
    uint32_t part, parts;
    uint64_t load;
} box_task;

static void* keys_thread(void* arg) {
    box_task* t = (box_task*)arg;
    const akp_boids_ctx* c = t->c;
    const size_t dimx = (size_t)c->dense_dim[0], dimxy = dimx * (size_t)c->dense_dim[1];
    const int32_t* cells = t->cells;
    for (size_t i = c->n * t->part / t->parts, e = c->n * (t->part + 1) / t->parts; i < e; ++i)
        t->keys[i] = (uint32_t)((size_t)(cells[3 * i + 2] - c->dense_min[2]) * dimxy +
                                (size_t)(cells[3 * i + 1] - c->dense_min[1]) * dimx +
                                (size_t)(cells[3 * i] - c->dense_min[0]));
    return NULL;
}

static void* load_thread(void* arg) {
    box_task* t = (box_task*)arg;
    uint64_t load = 0;
    for (size_t b = t->volume * t->part / t->parts, e = t->volume * (t->part + 1) / t->parts; b < e; ++b) {
        const uint64_t k = t->start[b + 1] - t->start[b];
        load += k * k;
    }
    t->load = load;
    return NULL;
}

static void run_parts(void* (*fn)(void*), void* tasks, size_t size, uint32_t parts) {
    if (parts == 1) fn(tasks);
    else akp_boids_run_tasks(fn, tasks, size, parts);
}

/* The job's budget on the sum over cells of (agents in the cell)^2 (boids.h). */
static uint64_t cell_budget(const akp_boids_ctx* c) {
    return c->job->max_cell_load ? c->job->max_cell_load : AK_BOIDS_DEFAULT_CELL_LOAD;
}

ak_result akp_boids_search_prepare(akp_boids_ctx* c, ak_u8_span scratch) {
    float search;
    const float cs = cell_size_for(c->params, &search);
    c->search_radius = search;
    if (c->job->use_naive || cs <= 0.0f) return AK_OK;
    const size_t n = c->n;
    const ak_grid_desc gd = {.cell_size = cs};
    const size_t gbytes = ak_grid_memory_size(n, &gd);
    uint8_t* base = (uint8_t*)(((uintptr_t)scratch.ptr + 63u) & ~(uintptr_t)63u);
    c->rings = (int)ceilf(search / cs - 1e-6f);
    if (c->rings < 1) c->rings = 1;
    if (c->rings > MAX_RINGS) c->rings = MAX_RINGS;
    uint8_t* q = base + align64(gbytes);
    int64_t* qv = (int64_t*)(void*)q;
    q += align64(3 * n * sizeof(int64_t));
    uint8_t* sp = q;
    q += align64(n);
    uint32_t* dstart = (uint32_t*)(void*)q;
    q += align64((dense_cap(n) + 1) * sizeof(uint32_t));
    float* sx = (float*)(void*)q;
    q += align64(n * sizeof(float));
    float* sy = (float*)(void*)q;
    q += align64(n * sizeof(float));
    float* sz = (float*)(void*)q;
    q += align64(n * sizeof(float));
    ak_vec3* sv = (ak_vec3*)(void*)q;
    q += align64(n * sizeof(ak_vec3));
    uint32_t* sj = (uint32_t*)(void*)q;
    q += align64(n * sizeof(uint32_t));
    const bool sym_ok = sym_params(c->params);
    c->acc = sym_ok ? (akp_boids_acc*)(void*)q : NULL;
    const ak_vec3* V = c->job->velocities.ptr;
    const uint8_t* S = c->job->species.ptr;
    c->sqv = qv;
    c->ssp = sp;
    c->dstart = NULL;
    c->sym = false;
    memset(&c->grid, 0, sizeof c->grid);
    c->grid.cell_size = cs; /* what box_cell needs; the hashed grid is built only when sparse */
    /* The grid's memory holds the cell coordinates meanwhile (3n int32 fit: it has 4n + more). */
    int32_t* cells = (int32_t*)(void*)base;
    if (!dense_direct(c, cells)) {
        ak_result r = ak_grid_build(&gd, c->job->positions, (ak_u8_span){base, gbytes}, &c->grid);
        if (r != AK_OK) return r;
        /* Sparse flock: the grid's order, cells found through its hash. */
        const ak_grid* gr = &c->grid;
        uint64_t load = 0;
        for (uint32_t m = 0; m < gr->cell_count; ++m) {
            const uint64_t k = gr->cell_start[m + 1] - gr->cell_start[m];
            load += k * k;
        }
        if (load > cell_budget(c)) return AK_ERR_BUDGET;
        for (size_t k = 0; k < n; ++k) {
            const uint32_t j = gr->order[k];
            const uint8_t s = S ? S[j] : 0;
            const float as = c->sp[s].ali_scale;
            qv[3 * k] = fix(V[j].x * as);
            qv[3 * k + 1] = fix(V[j].y * as);
            qv[3 * k + 2] = fix(V[j].z * as);
            sp[k] = s;
        }
        return AK_OK;
    }
    /* Counting sort of the agents into the box's (z, y, x) cell order, stable, over the team
     * (src/csort.h; the same order for any thread count): the box indices go to sx, the sort's
     * scratch to qv (both filled only later, by akp_boids_search_fill). */
    const size_t volume = (size_t)c->dense_dim[0] * (size_t)c->dense_dim[1] * (size_t)c->dense_dim[2];
    const uint32_t sort_parts = n < 2048 ? 1u : akp_boids_threads(c->job->thread_count, n);
    uint32_t* keys = (uint32_t*)(void*)sx;
    {
        box_task tasks[64];
        for (uint32_t t = 0; t < sort_parts; ++t) tasks[t] = (box_task){c, cells, keys, NULL, volume, t, sort_parts, 0};
        run_parts(keys_thread, tasks, sizeof tasks[0], sort_parts);
        akp_csort cs_store; /* 16 KiB of counts: on the stack, not in the context */
        akp_csort* cs = &cs_store;
        *cs = (akp_csort){.keys = keys, .n = n, .buckets = (uint32_t)volume, .parts = sort_parts, .order = sj,
                          .start = dstart, .tmp = (uint32_t*)(void*)qv};
        akp_csort_run(cs);
        /* the budget: the sum over cells of (agents in the cell)^2, per range of cells */
        for (uint32_t t = 0; t < sort_parts; ++t) tasks[t].start = dstart;
        run_parts(load_thread, tasks, sizeof tasks[0], sort_parts);
        uint64_t load = 0;
        for (uint32_t t = 0; t < sort_parts; ++t) load += tasks[t].load;
        if (load > cell_budget(c)) return AK_ERR_BUDGET;
    }
    c->sx = sx;
    c->sy = sy;
    c->sz = sz;
    c->sv = sv;
    c->sj = sj;
    c->dstart = dstart;
    c->fill_sx = sx;
    c->fill_sy = sy;
    c->fill_sz = sz;
    c->fill_sv = sv;
    c->fill_sp = sp;
    c->fill_qv = qv;
    /* The agents' data in spatial order: read through sj (in order), written in order, so it
     * splits over threads (akp_boids_search_fill); small steps fill here. */
    c->sym = sym_ok && c->rings == 1;
    /* The grid's memory is free on this path (the cell coordinates are done with). */
    c->spill = (akp_boids_acc*)(void*)base;
    c->spill_cap = gbytes / sizeof(akp_boids_acc);
    const uint32_t parts = akp_boids_threads(c->job->thread_count, n);
    if (parts <= 1 || n < 2048) akp_boids_search_fill(c, 0, 1);
    else {
        /* the step's partition, and the symmetric pass's deferred sums zeroed in the fill */
        akp_boids_partition(c, parts);
        if (c->sym) sym_plan(c, parts);
        akp_boids_fill_task tasks[64];
        for (uint32_t t = 0; t < parts; ++t) tasks[t] = (akp_boids_fill_task){c, t, parts};
        akp_boids_run_tasks(fill_thread, tasks, sizeof tasks[0], parts);
        c->sym_zeroed = c->sym;
    }
    c->avx512 = !c->job->skip_simd && !c->job->skip_avx512 && akp_boids_have_avx512();
    c->avx2 = !c->job->skip_simd && !c->avx512 && akp_boids_have_avx2();
    c->one_species = c->params->species_count == 1;
    return AK_OK;
}

const char* ak_boids_simd_name(void) {
#if AK_SIMD_SSE2
    return akp_boids_have_avx512() ? "avx512" : akp_boids_have_avx2() ? "avx2" : "sse2";
#else
    return "scalar";
#endif
}

/* ---- drivers ----------------------------------------------------------------------------- */

/* The search for one agent whose gather_begin is done, on whichever path the step uses. */
static void gather_search(const akp_boids_ctx* c, akp_boids_gather* g) {
    if (c->job->use_naive) gather_naive(c, g);
    else if (c->dstart) {
        int64_t x, y, z;
        row_ranges rr;
        box_cell(c, g->p, &x, &y, &z);
        rows_around(c, x, y, z, &rr);
        gather_rows(c, &rr, g);
    } else {
        cell_ranges r;
        ranges_around(c, ak_grid_cell_of(&c->grid, g->p), &r);
        gather_cells(c, &r, g);
    }
}

void akp_boids_gather_agent(const akp_boids_ctx* c, size_t i, akp_boids_gather* g) {
    gather_begin(c, i, g);
    if (c->search_radius <= 0.0f) return;
    gather_search(c, g);
    gather_end(c, g);
}

/* Heap sort of a neighbour list by (distance^2, index); d2 recomputed from the positions. */
static float dist2(const akp_boids_ctx* c, const akp_boids_gather* g, uint32_t j) {
    const ak_vec3 q = c->job->positions.ptr[j];
    const float dx = q.x - g->p.x, dy = q.y - g->p.y, dz = q.z - g->p.z;
    return dx * dx + dy * dy + dz * dz;
}

static void sift(const akp_boids_ctx* c, const akp_boids_gather* g, uint32_t* a, size_t root, size_t n) {
    for (;;) {
        size_t child = 2 * root + 1;
        if (child >= n) return;
        if (child + 1 < n && closer(dist2(c, g, a[child]), a[child], dist2(c, g, a[child + 1]), a[child + 1]))
            ++child;
        if (!closer(dist2(c, g, a[root]), a[root], dist2(c, g, a[child]), a[child])) return;
        const uint32_t t = a[root];
        a[root] = a[child];
        a[child] = t;
        root = child;
    }
}

void akp_boids_list_agent(const akp_boids_ctx* c, size_t i, uint32_t* out, uint32_t count) {
    akp_boids_gather g;
    gather_begin(c, i, &g);
    if (c->search_radius <= 0.0f || count == 0) return;
    g.list = out;
    gather_search(c, &g);
    gather_end(c, &g);
    AK_ASSERT(g.list_count == count);
    const size_t n = g.list_count;
    for (size_t k = n / 2; k-- > 0;) sift(c, &g, out, k, n);
    for (size_t e = n; e-- > 1;) {
        const uint32_t t = out[0];
        out[0] = out[e];
        out[e] = t;
        sift(c, &g, out, 0, e);
    }
}

void akp_boids_gather_range(const akp_boids_ctx* c, size_t part, size_t parts, akp_boids_agent_fn fn, void* user) {
    akp_boids_gather g;
    const size_t n = c->n;
    const size_t b = n * part / parts, e = n * (part + 1) / parts;
    if (c->job->use_naive || c->search_radius <= 0.0f) {
        for (size_t i = b; i < e; ++i) {
            akp_boids_gather_agent(c, i, &g);
            fn(c, i, &g, user);
        }
        return;
    }
    if (c->dstart) {
        /* Box cells in spatial order (neighbouring cells share their candidates in cache), the
         * rows split between the threads by estimated work (akp_boids_partition; whole rows by
         * count if it was not made for these parts). */
        const int32_t* dim = c->dense_dim;
        const size_t rows = (size_t)dim[1] * (size_t)dim[2];
        const bool planned = c->part_count == parts;
        const size_t r0 = planned ? c->part_row[part] : rows * part / parts;
        const size_t r1 = planned ? c->part_row[part + 1] : rows * (part + 1) / parts;
        row_ranges rr;
        for (size_t rw = r0; rw < r1; ++rw) {
            const size_t z = rw / (size_t)dim[1], y = rw % (size_t)dim[1];
            const size_t row = rw * (size_t)dim[0];
            for (size_t x = 0; x < (size_t)dim[0]; ++x) {
                const uint32_t k0 = c->dstart[row + x], k1 = c->dstart[row + x + 1];
                if (k0 == k1) continue;
                rows_around(c, (int64_t)x, (int64_t)y, (int64_t)z, &rr);
                for (uint32_t k = k0; k < k1; ++k) {
                    gather_begin_spatial(c, k, &g);
                    gather_rows(c, &rr, &g);
                    gather_end(c, &g);
                    fn(c, g.i, &g, user);
                }
            }
        }
        return;
    }
    const ak_grid* gr = &c->grid;
    cand_buf bufv; /* 24 KiB on this thread's stack */
    cand_buf* buf = &bufv;
    cell_ranges r;
    /* Cells whose first sorted entry falls in [b, e): each cell's neighbour cells once. */
    uint32_t lo = 0, hi = gr->cell_count;
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (gr->cell_start[mid] < b) lo = mid + 1;
        else hi = mid;
    }
    for (uint32_t m = lo; m < gr->cell_count && gr->cell_start[m] < e; ++m) {
        const uint32_t k0 = gr->cell_start[m], k1 = gr->cell_start[m + 1];
        ranges_around(c, gr->cell_coord[m], &r);
        const bool buffered = cand_fill(c, &r, buf);
        for (uint32_t k = k0; k < k1; ++k) {
            const uint32_t i = gr->order[k];
            gather_begin(c, i, &g);
            if (buffered) gather_buffered(buf, &g);
            else gather_cells(c, &r, &g);
            gather_end(c, &g);
            fn(c, i, &g, user);
        }
    }
}
