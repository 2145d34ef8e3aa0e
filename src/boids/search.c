/* Boids neighbour search: the naive O(N^2) loop and the grid walk, behind one visit()
 * function, so both paths apply exactly the same tests to exactly the same candidates (the
 * grid only skips agents that are certainly too far). The sums are exact (fixed point), so
 * the order candidates arrive in does not matter; the k-nearest cap keeps the k smallest
 * (distance^2, index) pairs, a strict total order, so it does not depend on order either. */
#include <string.h>

#include "boids_internal.h"

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
    x = x > AKP_BOIDS_FIX_CLAMP ? AKP_BOIDS_FIX_CLAMP : (x < -AKP_BOIDS_FIX_CLAMP ? -AKP_BOIDS_FIX_CLAMP : x);
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
static inline void accumulate(const akp_boids_sp* S, akp_boids_gather* g, float dx, float dy, float dz, float d2,
                              float vx, float vy, float vz) {
    ++g->nflock;
    if (d2 < S->rs2) {
        const float inv = S->sep_scale / (d2 > S->dmin2 ? d2 : S->dmin2);
        g->sep[0] += fix(-dx * inv);
        g->sep[1] += fix(-dy * inv);
        g->sep[2] += fix(-dz * inv);
        ++g->ns;
    }
    if (d2 < S->ra2) {
        g->ali[0] += fix(vx * S->ali_scale);
        g->ali[1] += fix(vy * S->ali_scale);
        g->ali[2] += fix(vz * S->ali_scale);
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
static inline void visit(akp_boids_gather* g, uint32_t j, float dx, float dy, float dz, float d2, float vx,
                         float vy, float vz, uint8_t sj) {
    const akp_boids_sp* S = g->sp;
    if (j == g->i) return;
    if (sj == g->species && d2 < S->rn2 && in_view(S, g, dx, dy, dz, d2)) {
        if (S->s.k_nearest) keep_nearest(g, S->s.k_nearest, d2, j);
        else {
            if (g->list) g->list[g->list_count++] = j;
            accumulate(S, g, dx, dy, dz, d2, vx, vy, vz);
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
        accumulate(S, g, dx, dy, dz, g->kd2[a], V[j].x, V[j].y, V[j].z);
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
        visit(g, (uint32_t)j, dx, dy, dz, d2, V[j].x, V[j].y, V[j].z, sp ? sp[j] : 0);
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
            visit(g, gr->order[k], dx, dy, dz, d2, c->svx[k], c->svy[k], c->svz[k], c->ssp[k]);
        }
    }
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

size_t akp_boids_search_scratch_size(const ak_boids_step_job* job) {
    float search;
    const float cs = cell_size_for(job->params, &search);
    if (cs <= 0.0f || !ak_finitef(cs)) return 0;
    const size_t n = job->positions.count;
    const ak_grid_desc gd = {.cell_size = cs};
    const size_t g = ak_grid_memory_size(n, &gd);
    if (g == 0) return 0;
    return align64(g) + 3 * align64(n * sizeof(float)) + align64(n) + 64;
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
    float* vx = (float*)(void*)q;
    float* vy = (float*)(void*)(q + align64(n * sizeof(float)));
    float* vz = (float*)(void*)(q + 2 * align64(n * sizeof(float)));
    uint8_t* sp = q + 3 * align64(n * sizeof(float));
    const ak_vec3* V = c->job->velocities.ptr;
    const uint8_t* S = c->job->species.ptr;
    for (size_t k = 0; k < n; ++k) {
        const uint32_t j = c->grid.order[k];
        vx[k] = V[j].x;
        vy[k] = V[j].y;
        vz[k] = V[j].z;
        sp[k] = S ? S[j] : 0;
    }
    c->svx = vx;
    c->svy = vy;
    c->svz = vz;
    c->ssp = sp;
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
    /* Cells whose first sorted entry falls in [b, e): each cell's neighbour cells once. */
    const ak_grid* gr = &c->grid;
    uint32_t lo = 0, hi = gr->cell_count;
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (gr->cell_start[mid] < b) lo = mid + 1;
        else hi = mid;
    }
    cell_ranges r;
    for (uint32_t m = lo; m < gr->cell_count && gr->cell_start[m] < e; ++m) {
        const uint32_t k0 = gr->cell_start[m], k1 = gr->cell_start[m + 1];
        ranges_around(c, gr->cell_coord[m], &r);
        for (uint32_t k = k0; k < k1; ++k) {
            const uint32_t i = gr->order[k];
            gather_begin(c, i, &g);
            gather_cells(c, &r, &g);
            gather_end(c, &g);
            fn(c, i, &g, user);
        }
    }
}
