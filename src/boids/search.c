/* Boids neighbour search: the naive O(N^2) loop and the grid walk, behind one visit()
 * function, so both paths apply exactly the same tests to exactly the same candidates (the
 * grid only skips agents that are certainly too far). The sums are exact (fixed point), so
 * the order candidates arrive in does not matter; the k-nearest cap keeps the k smallest
 * (distance^2, index) pairs, a strict total order, so it does not depend on order either. */
#include <string.h>

#include "boids_internal.h"
#include "../simd.h"

/* ---- the per-candidate rules ----------------------------------------------------------- */

static void gather_begin(const akp_boids_ctx* c, size_t i, akp_boids_gather* g) {
    const ak_boids_step_job* job = c->job;
    const uint8_t s = job->species.ptr ? job->species.ptr[i] : 0;
    g->sp = &c->sp[s];
    g->i = (uint32_t)i;
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

static inline bool in_view(const akp_boids_sp* S, const akp_boids_gather* g, float dx, float dy, float dz,
                           float d2) {
    if (S->fov == 0 || g->v2 == 0.0f || d2 == 0.0f) return true;
    const float dot = dx * g->v.x + dy * g->v.y + dz * g->v.z;
    const float lim = S->cos2 * d2 * g->v2;
    if (S->fov == 1) return dot > 0.0f && dot * dot >= lim;
    return dot >= 0.0f || dot * dot <= lim;
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
    if (c->dense) {
        const int32_t* lo = c->dense_min;
        const int32_t* dim = c->dense_dim;
        const int64_t x0 = (int64_t)cc.x - lo[0], y0 = (int64_t)cc.y - lo[1], z0 = (int64_t)cc.z - lo[2];
        for (int64_t z = z0 - R; z <= z0 + R; ++z) {
            if (z < 0 || z >= dim[2]) continue;
            for (int64_t y = y0 - R; y <= y0 + R; ++y) {
                if (y < 0 || y >= dim[1]) continue;
                const uint32_t* row = c->dense + ((size_t)z * (size_t)dim[1] + (size_t)y) * (size_t)dim[0];
                for (int64_t x = x0 - R; x <= x0 + R; ++x) {
                    if (x < 0 || x >= dim[0]) continue;
                    const uint32_t m = row[x];
                    if (m == UINT32_MAX) continue;
                    r->begin[r->count] = gr->cell_start[m];
                    r->end[r->count] = gr->cell_start[m + 1];
                    ++r->count;
                }
            }
        }
        return;
    }
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
    g->sep[0] += s0;
    g->sep[1] += s1;
    g->sep[2] += s2;
    g->ali[0] += a0;
    g->ali[1] += a1;
    g->ali[2] += a2;
    g->coh[0] += c0;
    g->coh[1] += c1;
    g->coh[2] += c2;
    g->ns += ns;
    g->na += na;
    g->nc += nc;
    g->nflock += nf;
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

static void build_dense(akp_boids_ctx* c, uint32_t* table) {
    const ak_grid* gr = &c->grid;
    c->dense = NULL;
    if (gr->cell_count == 0) return;
    int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {INT64_MIN, INT64_MIN, INT64_MIN};
    for (uint32_t m = 0; m < gr->cell_count; ++m) {
        const int64_t v[3] = {gr->cell_coord[m].x, gr->cell_coord[m].y, gr->cell_coord[m].z};
        for (int a = 0; a < 3; ++a) {
            if (v[a] < lo[a]) lo[a] = v[a];
            if (v[a] > hi[a]) hi[a] = v[a];
        }
    }
    const int64_t dx = hi[0] - lo[0] + 1, dy = hi[1] - lo[1] + 1, dz = hi[2] - lo[2] + 1;
    const size_t cap = dense_cap(c->n);
    if (dx > (int64_t)cap || dy > (int64_t)cap || dz > (int64_t)cap || dx * dy > (int64_t)cap ||
        dx * dy * dz > (int64_t)cap)
        return;
    const size_t volume = (size_t)(dx * dy * dz);
    memset(table, 0xFF, volume * sizeof(uint32_t));
    for (uint32_t m = 0; m < gr->cell_count; ++m) {
        const ak_grid_cell q = gr->cell_coord[m];
        table[((size_t)(q.z - lo[2]) * (size_t)dy + (size_t)(q.y - lo[1])) * (size_t)dx + (size_t)(q.x - lo[0])] = m;
    }
    c->dense = table;
    c->dense_min[0] = (int32_t)lo[0];
    c->dense_min[1] = (int32_t)lo[1];
    c->dense_min[2] = (int32_t)lo[2];
    c->dense_dim[0] = (int32_t)dx;
    c->dense_dim[1] = (int32_t)dy;
    c->dense_dim[2] = (int32_t)dz;
}

size_t akp_boids_search_scratch_size(const ak_boids_step_job* job) {
    float search;
    const float cs = cell_size_for(job->params, &search);
    if (cs <= 0.0f || !ak_finitef(cs)) return 0;
    const size_t n = job->positions.count;
    const ak_grid_desc gd = {.cell_size = cs};
    const size_t g = ak_grid_memory_size(n, &gd);
    if (g == 0) return 0;
    return align64(g) + align64(3 * n * sizeof(int64_t)) + align64(n) + dense_cap(n) * sizeof(uint32_t) + 64;
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
    ak_result r = ak_grid_build(&gd, c->job->positions, (ak_u8_span){base, gbytes}, &c->grid);
    if (r != AK_OK) return r;
    c->rings = (int)ceilf(search / cs - 1e-6f);
    if (c->rings < 1) c->rings = 1;
    if (c->rings > MAX_RINGS) c->rings = MAX_RINGS;
    uint8_t* q = base + align64(gbytes);
    int64_t* qv = (int64_t*)(void*)q;
    uint8_t* sp = q + align64(3 * n * sizeof(int64_t));
    const ak_vec3* V = c->job->velocities.ptr;
    const uint8_t* S = c->job->species.ptr;
    for (size_t k = 0; k < n; ++k) {
        const uint32_t j = c->grid.order[k];
        const uint8_t sj = S ? S[j] : 0;
        const float as = c->sp[sj].ali_scale;
        qv[3 * k] = fix(V[j].x * as);
        qv[3 * k + 1] = fix(V[j].y * as);
        qv[3 * k + 2] = fix(V[j].z * as);
        sp[k] = sj;
    }
    c->sqv = qv;
    c->ssp = sp;
    build_dense(c, (uint32_t*)(void*)(sp + align64(n)));
    return AK_OK;
}

/* ---- drivers ----------------------------------------------------------------------------- */

void akp_boids_gather_agent(const akp_boids_ctx* c, size_t i, akp_boids_gather* g) {
    gather_begin(c, i, g);
    if (c->search_radius <= 0.0f) return;
    if (c->job->use_naive) gather_naive(c, g);
    else {
        cell_ranges r;
        ranges_around(c, ak_grid_cell_of(&c->grid, g->p), &r);
        gather_cells(c, &r, g);
    }
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
    if (c->job->use_naive) gather_naive(c, &g);
    else {
        cell_ranges r;
        ranges_around(c, ak_grid_cell_of(&c->grid, g.p), &r);
        gather_cells(c, &r, &g);
    }
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
    const ak_grid* gr = &c->grid;
    cand_buf bufv; /* 24 KiB on this thread's stack */
    cand_buf* buf = &bufv;
    cell_ranges r;
    if (c->dense) {
        /* Cells in spatial order (neighbouring cells share their candidates in cache), the
         * z slabs split between the threads. */
        const int32_t* dim = c->dense_dim;
        const size_t z0 = (size_t)dim[2] * part / parts, z1 = (size_t)dim[2] * (part + 1) / parts;
        const size_t slab = (size_t)dim[0] * (size_t)dim[1];
        for (size_t cell = z0 * slab; cell < z1 * slab; ++cell) {
            const uint32_t m = c->dense[cell];
            if (m == UINT32_MAX) continue;
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
        return;
    }
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
