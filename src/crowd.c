/* Crowds: ORCA (van den Berg, Guy, Lin, Manocha 2011) on the shared neighbour grid.
 *
 * The arithmetic follows the paper's construction in single precision, in the order its
 * reference library evaluates it, so that trajectories can be compared with RVO2 bit for bit
 * up to the neighbour order (bench/vs_rvo2). Each agent reads only the step's inputs and
 * writes its own outputs: threads split agents into ranges and results do not depend on the
 * split. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include <animkit/crowd.h>
#include <animkit/grid.h>
#include <animkit/raster.h>

#include "internal.h"
#include "tasks.h"

#if !defined(AK_NO_SIMD) && (defined(__SSE2__) || defined(_M_X64) || defined(_M_AMD64))
#define CROWD_SSE2 1
#include <xmmintrin.h>
#else
#define CROWD_SSE2 0
#endif

#define EPS 1e-5f   /* the LP's parallel-line tolerance (RVO2's RVO_EPSILON) */
#define COORD_MAX 1e7f

/* ---- private types --------------------------------------------------------------------- */

typedef struct obst_vertex {
    ak_vec2 point;
    ak_vec2 direction; /* unit, toward next */
    uint32_t next, prev;
    bool convex;
} obst_vertex;

struct ak_crowd {
    ak_allocator alloc;
    size_t agent_count;
    ak_crowd_agent* agents; /* resolved; goals point into waypoints */
    float* radii;           /* [agent_count] agents[i].radius, compact for the neighbour loops */
    ak_vec2* waypoints;
    obst_vertex* verts;
    uint32_t vertex_count;
    ak_crowd_method method;
    uint32_t vision_width;
    float vision_fov; /* radians */
    ak_crowd_view vision_view;
    uint32_t vision_height;
    float max_neighbor_distance;
    float max_radius;
    uint32_t max_k;
    float cell_size;
};

typedef struct neigh {
    float dist_sq;
    uint32_t index;
} neigh;

/* ---- small vector helpers (single precision, as written in the paper) ------------------ */

static inline ak_vec2 v2(float x, float y) { ak_vec2 r = {x, y}; return r; }
static inline ak_vec2 add(ak_vec2 a, ak_vec2 b) { return v2(a.x + b.x, a.y + b.y); }
static inline ak_vec2 sub(ak_vec2 a, ak_vec2 b) { return v2(a.x - b.x, a.y - b.y); }
static inline ak_vec2 mul(float s, ak_vec2 a) { return v2(s * a.x, s * a.y); }
/* Division as a multiplication by the reciprocal (RVO2's Vector2 divides this way). */
static inline ak_vec2 divs(ak_vec2 a, float s) {
    const float inv = 1.0f / s;
    return v2(a.x * inv, a.y * inv);
}
static inline ak_vec2 neg(ak_vec2 a) { return v2(-a.x, -a.y); }
static inline float dot(ak_vec2 a, ak_vec2 b) { return a.x * b.x + a.y * b.y; }
static inline float det(ak_vec2 a, ak_vec2 b) { return a.x * b.y - a.y * b.x; }
static inline float abs_sq(ak_vec2 a) { return dot(a, a); }
static inline float len(ak_vec2 a) { return sqrtf(abs_sq(a)); }
/* A zero vector (agents on the same point, an agent on a vertex) has no direction: +x then,
 * so that degenerate input gives a finite answer (RVO2 divides by zero there). */
static inline ak_vec2 normalize(ak_vec2 a) {
    const float l = len(a);
    return l > 0.0f ? divs(a, l) : v2(1.0f, 0.0f);
}
/* > 0 when c lies left of the directed line a -> b. */
static inline float left_of(ak_vec2 a, ak_vec2 b, ak_vec2 c) { return det(sub(a, c), sub(b, a)); }

static bool finite_in(float x, float lim) { return ak_finitef(x) && fabsf(x) <= lim; }

/* ---- agents and the crowd object ---------------------------------------------------------- */

ak_crowd_agent ak_crowd_agent_resolved(const ak_crowd_agent* agent) {
    ak_crowd_agent a;
    if (agent) a = *agent;
    else memset(&a, 0, sizeof a);
    if (a.radius == 0.0f) a.radius = 0.3f;
    if (a.pref_speed == 0.0f) a.pref_speed = 1.3f;
    if (a.max_speed == 0.0f) a.max_speed = ak_maxf(2.0f, a.pref_speed);
    if (a.neighbor_distance == 0.0f) a.neighbor_distance = 5.0f;
    if (a.max_neighbors == 0) a.max_neighbors = 10;
    if (a.time_horizon == 0.0f) a.time_horizon = 2.0f;
    if (a.time_horizon_obstacles == 0.0f) a.time_horizon_obstacles = 2.0f;
    if (a.waypoint_radius == 0.0f) a.waypoint_radius = a.radius;
    return a;
}

static bool agent_ok(const ak_crowd_agent* a) {
    const float f[] = {a->radius,       a->pref_speed,   a->max_speed,           a->neighbor_distance,
                       a->time_horizon, a->time_horizon_obstacles, a->waypoint_radius};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i)
        if (!(f[i] >= 0.0f) || !finite_in(f[i], COORD_MAX)) return false;
    if (a->max_neighbors > AK_CROWD_MAX_NEIGHBORS) return false;
    const ak_crowd_agent r = ak_crowd_agent_resolved(a);
    return r.max_speed >= r.pref_speed;
}

ak_result ak_crowd_create(const ak_crowd_desc* desc, const ak_allocator* alloc, ak_crowd** out_crowd) {
    if (out_crowd) *out_crowd = NULL;
    if (!desc || !out_crowd || !desc->agents.ptr) return AK_ERR_NULL_ARG;
    if (desc->obstacle_count > 0 && !desc->obstacles) return AK_ERR_NULL_ARG;
    const size_t n = desc->agents.count;
    size_t wp_total = 0, vert_total = 0;
    for (size_t i = 0; i < n && i <= AK_CROWD_MAX_AGENTS; ++i) {
        if (!desc->agents.ptr[i].goals.ptr && desc->agents.ptr[i].goals.count > 0) return AK_ERR_NULL_ARG;
        wp_total += desc->agents.ptr[i].goals.count;
        if (wp_total > AK_CROWD_MAX_WAYPOINTS) return AK_ERR_BAD_ARG;
    }
    for (uint32_t o = 0; o < desc->obstacle_count && o <= AK_CROWD_MAX_OBSTACLE_VERTICES; ++o) {
        if (!desc->obstacles[o].vertices.ptr) return AK_ERR_NULL_ARG;
        vert_total += desc->obstacles[o].vertices.count;
        if (vert_total > AK_CROWD_MAX_OBSTACLE_VERTICES) return AK_ERR_BAD_ARG;
    }
    if (n > AK_CROWD_MAX_AGENTS || (unsigned)desc->method >= AK_CROWD_METHOD_COUNT || desc->vision_width > 1024 ||
        !(desc->vision_fov >= 0.0f && desc->vision_fov < 360.0f) || (unsigned)desc->vision_view >= AK_CROWD_VIEW_COUNT ||
        desc->vision_height > 256 || (desc->vision_view == AK_CROWD_VIEW_RASTER && !(desc->vision_fov < 180.0f)) ||
        desc->obstacle_count > AK_CROWD_MAX_OBSTACLE_VERTICES)
        return AK_ERR_BAD_ARG;
    if (n == 0) return AK_ERR_EMPTY;
    for (size_t i = 0; i < n; ++i) {
        if (desc->agents.ptr[i].goals.count == 0) return AK_ERR_EMPTY;
        if (!agent_ok(&desc->agents.ptr[i])) return AK_ERR_BAD_ARG;
    }
    for (uint32_t o = 0; o < desc->obstacle_count; ++o)
        if (desc->obstacles[o].vertices.count < 2) return AK_ERR_BAD_ARG;
    for (size_t i = 0; i < n; ++i)
        for (size_t k = 0; k < desc->agents.ptr[i].goals.count; ++k) {
            const ak_vec2 g = desc->agents.ptr[i].goals.ptr[k];
            if (!finite_in(g.x, COORD_MAX) || !finite_in(g.y, COORD_MAX)) return AK_ERR_BAD_DATA;
        }
    for (uint32_t o = 0; o < desc->obstacle_count; ++o) {
        const ak_vec2_cspan vs = desc->obstacles[o].vertices;
        for (size_t k = 0; k < vs.count; ++k) {
            const ak_vec2 g = vs.ptr[k];
            if (!finite_in(g.x, COORD_MAX) || !finite_in(g.y, COORD_MAX)) return AK_ERR_BAD_DATA;
        }
        for (size_t k = 0; k < vs.count; ++k) { /* every edge has a length */
            const ak_vec2 e = sub(vs.ptr[(k + 1) % vs.count], vs.ptr[k]);
            if (!(abs_sq(e) > 0.0f)) return AK_ERR_BAD_DATA;
        }
    }

    const size_t s_head = akp_align16(sizeof(ak_crowd));
    const size_t s_agents = akp_align16(n * sizeof(ak_crowd_agent));
    const size_t s_wp = akp_align16(wp_total * sizeof(ak_vec2));
    const size_t s_verts = akp_align16(vert_total * sizeof(obst_vertex));
    const size_t s_radii = akp_align16(n * sizeof(float));
    char* mem = (char*)akp_calloc(alloc, s_head + s_agents + s_wp + s_verts + s_radii);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_crowd* c = (ak_crowd*)(void*)mem;
    if (alloc) c->alloc = *alloc;
    c->agent_count = n;
    c->agents = (ak_crowd_agent*)(void*)(mem + s_head);
    c->waypoints = (ak_vec2*)(void*)(mem + s_head + s_agents);
    c->verts = (obst_vertex*)(void*)(mem + s_head + s_agents + s_wp);
    c->radii = (float*)(void*)(mem + s_head + s_agents + s_wp + s_verts);
    c->vertex_count = (uint32_t)vert_total;
    c->method = desc->method;
    c->vision_width = desc->vision_width ? desc->vision_width : 48;
    c->vision_fov = (desc->vision_fov > 0.0f ? desc->vision_fov : 150.0f) * (3.14159265358979f / 180.0f);
    c->vision_view = desc->vision_view;
    c->vision_height = desc->vision_height ? desc->vision_height : 8;
    size_t w = 0;
    for (size_t i = 0; i < n; ++i) {
        ak_crowd_agent a = ak_crowd_agent_resolved(&desc->agents.ptr[i]);
        memcpy(c->waypoints + w, a.goals.ptr, a.goals.count * sizeof(ak_vec2));
        a.goals.ptr = c->waypoints + w;
        w += a.goals.count;
        c->agents[i] = a;
        c->radii[i] = a.radius;
        c->max_neighbor_distance = ak_maxf(c->max_neighbor_distance, a.neighbor_distance);
        c->max_radius = ak_maxf(c->max_radius, a.radius);
        if (a.max_neighbors > c->max_k) c->max_k = a.max_neighbors;
    }
    /* Obstacles: a ring of vertices per polygon, each with its edge direction and convexity
     * (a segment's two vertices are both convex). */
    uint32_t v = 0;
    for (uint32_t o = 0; o < desc->obstacle_count; ++o) {
        const ak_vec2* p = desc->obstacles[o].vertices.ptr;
        const uint32_t m = (uint32_t)desc->obstacles[o].vertices.count;
        for (uint32_t k = 0; k < m; ++k) {
            obst_vertex* ov = &c->verts[v + k];
            ov->point = p[k];
            ov->next = v + (k + 1 == m ? 0 : k + 1);
            ov->prev = v + (k == 0 ? m - 1 : k - 1);
            ov->convex = m == 2 || left_of(p[k == 0 ? m - 1 : k - 1], p[k], p[k + 1 == m ? 0 : k + 1]) >= 0.0f;
            const ak_vec2 e = sub(p[k + 1 == m ? 0 : k + 1], p[k]);
            ov->direction = abs_sq(e) > 0.0f ? normalize(e) : v2(1.0f, 0.0f);
        }
        v += m;
    }
    /* Cells a quarter of the neighbour distance: the ring search stops as soon as the
     * max_neighbors nearest are found, which in a dense crowd is well inside that distance. */
    c->cell_size = ak_maxf(c->max_neighbor_distance * 0.25f, 1e-3f);
    *out_crowd = c;
    return AK_OK;
}

void ak_crowd_destroy(ak_crowd* crowd) {
    if (!crowd) return;
    const ak_allocator a = crowd->alloc;
    akp_free(a.alloc ? &a : NULL, crowd);
}

size_t ak_crowd_agent_count(const ak_crowd* crowd) { return crowd ? crowd->agent_count : 0; }

ak_crowd_agent ak_crowd_agent_get(const ak_crowd* crowd, size_t index) {
    ak_crowd_agent a;
    memset(&a, 0, sizeof a);
    if (crowd && index < crowd->agent_count) a = crowd->agents[index];
    return a;
}

bool ak_crowd_goal_reached(const ak_crowd* crowd, size_t index, ak_vec2 position, uint32_t waypoint) {
    if (!crowd || index >= crowd->agent_count) return false;
    const ak_crowd_agent* a = &crowd->agents[index];
    if ((size_t)waypoint + 1 < a->goals.count) return false;
    const ak_vec2 g = a->goals.ptr[a->goals.count - 1];
    return abs_sq(sub(position, g)) <= a->radius * a->radius;
}

/* ---- the linear programs ------------------------------------------------------------------- */

/* 1D program on line `no` (within the speed disc and the lines before it). */
static bool lp1(const ak_crowd_line* lines, size_t no, float radius, ak_vec2 opt, bool dir_opt, ak_vec2* result) {
    const ak_crowd_line L = lines[no];
    const float dp = dot(L.point, L.direction);
    const float disc = dp * dp + radius * radius - abs_sq(L.point);
    if (disc < 0.0f) return false; /* the line misses the speed disc */
    const float sq = sqrtf(disc);
    float t_left = -dp - sq, t_right = -dp + sq;
    for (size_t i = 0; i < no; ++i) {
        const float denom = det(L.direction, lines[i].direction);
        const float numer = det(lines[i].direction, sub(L.point, lines[i].point));
        if (fabsf(denom) <= EPS) { /* parallel */
            if (numer < 0.0f) return false;
            continue;
        }
        const float t = numer / denom;
        if (denom >= 0.0f) t_right = ak_minf(t_right, t);
        else t_left = ak_maxf(t_left, t);
        if (t_left > t_right) return false;
    }
    if (dir_opt) {
        *result = dot(opt, L.direction) > 0.0f ? add(L.point, mul(t_right, L.direction))
                                                : add(L.point, mul(t_left, L.direction));
    } else {
        const float t = dot(L.direction, sub(opt, L.point));
        if (t < t_left) *result = add(L.point, mul(t_left, L.direction));
        else if (t > t_right) *result = add(L.point, mul(t_right, L.direction));
        else *result = add(L.point, mul(t, L.direction));
    }
    return true;
}

#if CROWD_SSE2
/* Bit k set when line k of lines[0, 4) has r on its right (det(direction, point - r) > 0). */
static inline int violated4(const ak_crowd_line* l, ak_vec2 r) {
    __m128 a = _mm_loadu_ps(&l[0].point.x), b = _mm_loadu_ps(&l[1].point.x); /* px py dx dy */
    __m128 c = _mm_loadu_ps(&l[2].point.x), d = _mm_loadu_ps(&l[3].point.x);
    _MM_TRANSPOSE4_PS(a, b, c, d); /* a: px of the four lines, b: py, c: dx, d: dy */
    const __m128 ex = _mm_sub_ps(a, _mm_set1_ps(r.x)), ey = _mm_sub_ps(b, _mm_set1_ps(r.y));
    const __m128 dt = _mm_sub_ps(_mm_mul_ps(c, ey), _mm_mul_ps(d, ex));
    return _mm_movemask_ps(_mm_cmpgt_ps(dt, _mm_setzero_ps()));
}
static inline int ctz4(int m) { return (m & 1) ? 0 : (m & 2) ? 1 : (m & 4) ? 2 : 3; }
#endif

/* 2D program (incremental, Seidel-style in input order). Returns the first line that could
 * not be satisfied, or count. */
static size_t lp2(const ak_crowd_line* lines, size_t count, float radius, ak_vec2 opt, bool dir_opt, ak_vec2* result) {
    if (dir_opt) *result = mul(radius, opt);
    else if (abs_sq(opt) > radius * radius) *result = mul(radius, normalize(opt));
    else *result = opt;
    for (size_t i = 0; i < count; ++i) {
#if CROWD_SSE2
        /* four lines at a time: skip to the first the current result violates (the same
         * products and differences as det(), so the same bits) */
        while (i + 4 <= count) {
            const int m = violated4(lines + i, *result);
            if (m) {
                i += (size_t)ctz4(m);
                break;
            }
            i += 4;
        }
        if (i >= count) break;
#endif
        if (det(lines[i].direction, sub(lines[i].point, *result)) > 0.0f) {
            const ak_vec2 keep = *result;
            if (!lp1(lines, i, radius, opt, dir_opt, result)) {
                *result = keep;
                return i;
            }
        }
    }
    return count;
}

/* 3D program: minimise the largest violation of lines [begin, count) by a projection of the
 * earlier agent lines onto each violated one; obstacle lines stay hard. */
static void lp3(const ak_crowd_line* lines, size_t count, size_t obst_count, size_t begin, float radius,
                ak_crowd_line* proj, ak_vec2* result) {
    float distance = 0.0f;
    for (size_t i = begin; i < count; ++i) {
        if (det(lines[i].direction, sub(lines[i].point, *result)) > distance) {
            size_t np = obst_count;
            memcpy(proj, lines, obst_count * sizeof *proj);
            for (size_t j = obst_count; j < i; ++j) {
                ak_crowd_line l;
                const float d = det(lines[i].direction, lines[j].direction);
                if (fabsf(d) <= EPS) {
                    if (dot(lines[i].direction, lines[j].direction) > 0.0f) continue; /* same way */
                    l.point = mul(0.5f, add(lines[i].point, lines[j].point));
                } else {
                    l.point = add(lines[i].point,
                                  mul(det(lines[j].direction, sub(lines[i].point, lines[j].point)) / d,
                                      lines[i].direction));
                }
                l.direction = normalize(sub(lines[j].direction, lines[i].direction));
                proj[np++] = l;
            }
            const ak_vec2 keep = *result;
            if (lp2(proj, np, radius, v2(-lines[i].direction.y, lines[i].direction.x), true, result) < np)
                *result = keep; /* rounding: keep the previous solution */
            distance = det(lines[i].direction, sub(lines[i].point, *result));
        }
    }
}

ak_vec2 ak_crowd_solve(ak_crowd_line_cspan lines, size_t obstacle_line_count, float max_speed, ak_vec2 pref,
                       ak_crowd_line_span scratch, bool* out_feasible) {
    ak_vec2 r = v2(0.0f, 0.0f);
    if (out_feasible) *out_feasible = false;
    if ((lines.count > 0 && !lines.ptr) || obstacle_line_count > lines.count || !(max_speed >= 0.0f) ||
        !ak_finitef(pref.x) || !ak_finitef(pref.y))
        return r;
    const size_t fail = lp2(lines.ptr, lines.count, max_speed, pref, false, &r);
    if (fail < lines.count) {
        if (scratch.count >= lines.count && scratch.ptr)
            lp3(lines.ptr, lines.count, obstacle_line_count, fail, max_speed, scratch.ptr, &r);
    } else if (out_feasible) {
        *out_feasible = true;
    }
    return r;
}

/* ---- per-thread work ------------------------------------------------------------------------- */

typedef struct ctx {
    const ak_crowd_step_job* job;
    const ak_crowd* crowd;
    /* The neighbour search's grid: when the occupied rectangle of cells fits the scratch
     * (about 4 cells per agent), a dense one of our own, cells in row-major order with the
     * agents sorted by cell, so that a row of cells is one contiguous range (cstart != NULL);
     * else the shared hash grid. */
    const ak_grid* grid;
    const uint32_t* cstart; /* [w * h + 1]: cell (x, z) holds sorted entries
                               [cstart[z w + x], cstart[z w + x + 1]) */
    const float *sx, *sz;   /* [n] positions in cell order */
    const uint32_t* sidx;   /* [n] agent of each sorted entry */
    const ak_vec2* pref;    /* [n] every agent's preferred velocity this step (perturbed) */
    int64_t x0, z0;         /* the rectangle's first cell */
    int32_t w, h;
    float cs;
} ctx;

/* floor(v / cs) as the shared grid computes it (in double). */
static inline double cell_coord(float v, double inv_cs) { return floor((double)v * inv_cs); }

/* The dense grid over positions[0, n) into mem (cstart [cap + 1], sx, sz, sidx, cell [n]);
 * false when the rectangle has more than cap cells. *load: sum over cells of count^2. */
static bool dense_grid_build(ctx* c, const ak_vec2* P, size_t n, float cs, void* mem, size_t cap, uint64_t* load) {
    c->cstart = NULL;
    if (n == 0) return false;
    const double inv = 1.0 / (double)cs;
    double x0 = cell_coord(P[0].x, inv), x1 = x0, z0 = cell_coord(P[0].y, inv), z1 = z0;
    for (size_t i = 1; i < n; ++i) {
        const double x = cell_coord(P[i].x, inv), z = cell_coord(P[i].y, inv);
        x0 = x < x0 ? x : x0;
        x1 = x > x1 ? x : x1;
        z0 = z < z0 ? z : z0;
        z1 = z > z1 ? z : z1;
    }
    const double wd = x1 - x0 + 1.0, hd = z1 - z0 + 1.0;
    if (!(wd * hd <= (double)cap)) return false;
    const int32_t w = (int32_t)wd, h = (int32_t)hd;
    const size_t cells = (size_t)w * (size_t)h;
    uint32_t* cstart = (uint32_t*)mem;
    float* sx = (float*)(void*)(cstart + akp_align16((cap + 1) * sizeof(uint32_t)) / sizeof(uint32_t));
    float* sz = sx + akp_align16(n * sizeof(float)) / sizeof(float);
    uint32_t* sidx = (uint32_t*)(void*)(sz + akp_align16(n * sizeof(float)) / sizeof(float));
    uint32_t* cell = sidx + akp_align16(n * sizeof(uint32_t)) / sizeof(uint32_t);
    memset(cstart, 0, (cells + 1) * sizeof(uint32_t));
    for (size_t i = 0; i < n; ++i) {
        const uint32_t m = (uint32_t)((cell_coord(P[i].y, inv) - z0) * wd + (cell_coord(P[i].x, inv) - x0));
        cell[i] = m;
        ++cstart[m + 1];
    }
    uint64_t l = 0;
    for (size_t m = 0; m < cells; ++m) {
        l += (uint64_t)cstart[m + 1] * cstart[m + 1];
        cstart[m + 1] += cstart[m];
    }
    /* scatter in agent order (stable), cstart[m] advancing to the cell's end, then back */
    for (size_t i = 0; i < n; ++i) {
        const uint32_t s = cstart[cell[i]]++;
        sx[s] = P[i].x;
        sz[s] = P[i].y;
        sidx[s] = (uint32_t)i;
    }
    for (size_t m = cells; m > 0; --m) cstart[m] = cstart[m - 1];
    cstart[0] = 0;
    *load = l;
    c->cstart = cstart;
    c->sx = sx;
    c->sz = sz;
    c->sidx = sidx;
    c->x0 = (int64_t)x0;
    c->z0 = (int64_t)z0;
    c->w = w;
    c->h = h;
    c->cs = cs;
    return true;
}

/* Bytes of the dense grid for n agents and cap cells. */
static size_t dense_grid_bytes(size_t n, size_t cap) {
    return akp_align16((cap + 1) * sizeof(uint32_t)) + 2 * akp_align16(n * sizeof(float)) +
           2 * akp_align16(n * sizeof(uint32_t));
}

typedef struct worker {
    const ctx* c;
    size_t begin, end;
    uint64_t* agent_n;    /* [max_k] keys (nkey) */
    neigh* obst_n;        /* [vertex_count] */
    ak_crowd_line* lines; /* [max_k + vertex_count] */
    ak_crowd_line* proj;  /* [max_k + vertex_count] */
    struct vision_raster* vr; /* VISION RASTER: this worker's render target and buffers */
} worker;

/* A RASTER view's render target and buffers, one per worker, allocated for one step. */
typedef struct vision_raster {
    ak_raster* r;
    ak_vec3* pos;   /* [cap] triangle soup */
    ak_vec4* col;   /* [cap] flat id colours */
    uint8_t* rgba;  /* [W * H * 4] */
    float* depth;   /* [W * H] */
    size_t cap;
    float tan_half_fov; /* tan(vision_fov / 2) */
} vision_raster;

/* Agent neighbours are kept as one key each, (bits of the squared distance) << 32 | index:
 * distances are >= 0, so the keys order as (distance, index) do. */
static inline uint64_t nkey(float d, uint32_t j) {
    uint32_t b;
    memcpy(&b, &d, sizeof b);
    return (uint64_t)b << 32 | j;
}
static inline uint32_t nkey_index(uint64_t key) { return (uint32_t)key; }
static inline float nkey_dist(uint64_t key) {
    const uint32_t b = (uint32_t)(key >> 32);
    float d;
    memcpy(&d, &b, sizeof d);
    return d;
}

/* Sort keys[0, n) (n <= AK_CROWD_MAX_NEIGHBORS, all distinct: each holds its agent's index)
 * by rank: each key's place is the count of smaller keys. Branch-free compares, where a
 * sorted insertion of keys arriving in no order mispredicts its shifts (bench/vs_rvo2 10k:
 * 3.56x RVO2's speed against 3.24x, docs/BENCHMARKS.md). */
static void rank_sort(uint64_t* keys, uint32_t n) {
    uint64_t tmp[AK_CROWD_MAX_NEIGHBORS];
    for (uint32_t a = 0; a < n; ++a) {
        uint32_t r = 0;
        for (uint32_t b = 0; b < n; ++b) r += keys[b] < keys[a];
        tmp[r] = keys[a];
    }
    memcpy(keys, tmp, n * sizeof *keys);
}

/* Insert (d, j) into the list of the k nearest (by (distance, index), as RVO2 selects them).
 * The list is kept in no order: once full, a nearer key replaces the largest (*top: its
 * place), and the range shrinks to the largest's distance; neighbors_done rank-sorts it at
 * the end. The set, and then the order, are those of a sorted insertion (keys are distinct). */
static inline void insert_agent(uint64_t* list, uint32_t* count, uint32_t* top, uint32_t k, float* range_sq, float d,
                                uint32_t j) {
    if (!(d < *range_sq)) return;
    const uint64_t key = nkey(d, j);
    if (*count < k) {
        list[(*count)++] = key;
        if (*count < k) return;
    } else {
        list[*top] = key;
    }
    uint32_t t = 0;
    for (uint32_t q = 1; q < k; ++q) t = list[q] > list[t] ? q : t;
    *top = t;
    *range_sq = nkey_dist(list[t]);
}

/* The end of a search: the list in order. */
static inline uint32_t neighbors_done(uint64_t* list, uint32_t count) {
    rank_sort(list, count);
    return count;
}

/* ceil(x) for 0 <= x < 2^31 (no libm call). */
static inline int64_t ceil_nonneg(float x) {
    const int64_t t = (int64_t)x; /* truncation = floor for x >= 0 */
    return t + ((float)t < x);
}

/* The ring search on the dense grid: a ring's top and bottom rows are each one contiguous
 * range of sorted entries (cut to the cells within range), its sides single cells. */
static uint32_t agent_neighbors_dense(const ctx* c, size_t self, ak_vec2 p, const ak_crowd_agent* a, uint64_t* out) {
    uint32_t count = 0, top = 0;
    const uint32_t k = a->max_neighbors;
    float range_sq = a->neighbor_distance * a->neighbor_distance;
    const double inv = 1.0 / (double)c->cs;
    const int64_t hx = (int64_t)cell_coord(p.x, inv) - c->x0, hz = (int64_t)cell_coord(p.y, inv) - c->z0;
    const float cs = c->cs;
    /* the home cell's corner relative to p (cell bounds as the shared grid's) */
    const float bx = (float)(hx + c->x0) * cs - p.x, bz = (float)(hz + c->z0) * cs - p.y;
    const int64_t rmax = ceil_nonneg(a->neighbor_distance / cs) + 1;
    const uint32_t* cstart = c->cstart;
    const float *sx = c->sx, *sz = c->sz;
    const uint32_t* sidx = c->sidx;
    const uint32_t self32 = (uint32_t)self;
#define SCAN(s0, s1)                                                                                  \
    for (uint32_t s = (s0); s < (s1); ++s) {                                                          \
        const float ddx = p.x - sx[s], ddz = p.y - sz[s];                                             \
        const float d = ddx * ddx + ddz * ddz;                                                        \
        if (d < range_sq && sidx[s] != self32) insert_agent(out, &count, &top, k, &range_sq, d, sidx[s]); \
    }
    /* first the 5 x 3 block (rings 0 and 1, and ring 2's side cells of these rows): three
     * row ranges, the home row first; then ring 2's top and bottom rows; then rings >= 3 */
    {
        const int64_t xa = hx > 1 ? hx - 2 : 0, xb = hx + 2 < c->w ? hx + 2 : c->w - 1;
        for (int q = 0; q < 3; ++q) {
            const int64_t z = hz + (q == 0 ? 0 : q == 1 ? -1 : 1);
            if (z < 0 || z >= c->h) continue;
            const uint32_t* row = cstart + z * c->w;
            SCAN(row[xa], row[xb + 1])
        }
    }
    for (int64_t r = 2; r <= rmax; ++r) {
        const float md = (float)(r - 1) * cs;
        if (md * md * (1.0f - 1e-5f) >= range_sq) break; /* every cell of this ring is farther */
        /* rows dz = -r and dz = +r */
        for (int side = 0; side < 2; ++side) {
            const int64_t dz = side ? r : -r, z = hz + dz;
            if (z < 0 || z >= c->h) continue;
            int64_t xa = hx - r, xb = hx + r;
            const float lz = bz + (float)dz * cs;
            const float gz = ak_maxf(0.0f, ak_maxf(lz, -(lz + cs)));
            if (gz * gz * (1.0f - 1e-4f) >= range_sq) continue;
            /* cut the row to the cells whose nearest point is within range */
            while (xa <= xb) {
                const float lx = bx + (float)(xa - hx) * cs;
                const float gx = ak_maxf(0.0f, ak_maxf(lx, -(lx + cs)));
                if ((gx * gx + gz * gz) * (1.0f - 1e-4f) < range_sq) break;
                ++xa;
            }
            while (xb >= xa) {
                const float lx = bx + (float)(xb - hx) * cs;
                const float gx = ak_maxf(0.0f, ak_maxf(lx, -(lx + cs)));
                if ((gx * gx + gz * gz) * (1.0f - 1e-4f) < range_sq) break;
                --xb;
            }
            if (xa < 0) xa = 0;
            if (xb >= c->w) xb = c->w - 1;
            if (xa > xb) continue;
            const uint32_t* row = cstart + z * c->w;
            SCAN(row[xa], row[xb + 1])
        }
        if (r == 2) continue; /* its side cells were in the first block */
        /* columns dx = -r and dx = +r, rows -r+1 .. r-1 */
        for (int side = 0; side < 2; ++side) {
            const int64_t dx = side ? r : -r, x = hx + dx;
            if (x < 0 || x >= c->w) continue;
            const float lx = bx + (float)dx * cs;
            const float gx = ak_maxf(0.0f, ak_maxf(lx, -(lx + cs)));
            if (gx * gx * (1.0f - 1e-4f) >= range_sq) continue;
            for (int64_t dz = -r + 1; dz <= r - 1; ++dz) {
                const int64_t z = hz + dz;
                if (z < 0 || z >= c->h) continue;
                const float lz = bz + (float)dz * cs;
                const float gz = ak_maxf(0.0f, ak_maxf(lz, -(lz + cs)));
                if ((gx * gx + gz * gz) * (1.0f - 1e-4f) >= range_sq) continue;
                const uint32_t m = (uint32_t)(z * c->w + x);
                SCAN(cstart[m], cstart[m + 1])
            }
        }
    }
#undef SCAN
    return neighbors_done(out, count);
}

static uint32_t agent_neighbors(const ctx* c, size_t self, ak_vec2 p, const ak_crowd_agent* a, uint64_t* out) {
    if (a->max_neighbors == 0) return 0;
    if (c->cstart) return agent_neighbors_dense(c, self, p, a, out);
    const ak_grid* g = c->grid;
    uint32_t count = 0, top = 0;
    float range_sq = a->neighbor_distance * a->neighbor_distance;
    const ak_grid_cell home = ak_grid_cell_of(g, ak_vec3_make(p.x, 0.0f, p.y));
    const float cs = g->cell_size;
    const int32_t rmax = (int32_t)ceilf(a->neighbor_distance / cs) + 1;
    for (int32_t r = 0; r <= rmax; ++r) {
        if (r >= 2) {
            const float md = (float)(r - 1) * cs;
            if (md * md * (1.0f - 1e-5f) >= range_sq) break; /* every cell of this ring is farther */
        }
        const int32_t side = r == 0 ? 1 : 2 * r + 1;
        /* the ring: top and bottom rows in full, then the two side columns */
        for (int32_t e = 0; e < (r == 0 ? 1 : 8 * r); ++e) {
            int32_t dx, dz;
            if (r == 0) {
                dx = 0;
                dz = 0;
            } else if (e < side) {
                dx = e - r;
                dz = -r;
            } else if (e < 2 * side) {
                dx = e - side - r;
                dz = r;
            } else {
                const int32_t k = e - 2 * side; /* 0 .. 2(2r-1)-1 */
                dx = (k & 1) ? r : -r;
                dz = -r + 1 + (k >> 1);
            }
            if (r >= 2) {
                /* skip a cell whose nearest point is out of range (a margin for rounding) */
                const float lx = (float)(home.x + dx) * cs, lz = (float)(home.z + dz) * cs;
                const float gx = ak_maxf(0.0f, ak_maxf(lx - p.x, p.x - (lx + cs)));
                const float gz = ak_maxf(0.0f, ak_maxf(lz - p.y, p.y - (lz + cs)));
                if ((gx * gx + gz * gz) * (1.0f - 1e-4f) >= range_sq) continue;
            }
            const ak_grid_cell cc = {home.x + dx, 0, home.z + dz};
            const uint32_t m = ak_grid_cell_find(g, cc);
            if (m == UINT32_MAX) continue;
            for (uint32_t s = g->cell_start[m]; s < g->cell_start[m + 1]; ++s) {
                const uint32_t j = g->order[s];
                if (j == self) continue;
                const float dx2 = p.x - g->x[s], dz2 = p.y - g->z[s];
                const float d = dx2 * dx2 + dz2 * dz2;
                insert_agent(out, &count, &top, a->max_neighbors, &range_sq, d, j);
            }
        }
    }
    return neighbors_done(out, count);
}

/* Obstacle edges within range that the agent sees from their outer (right) side, nearest
 * first (ties in vertex order). */
static uint32_t obstacle_neighbors(const ak_crowd* c, ak_vec2 p, const ak_crowd_agent* a, neigh* out) {
    const float range = a->time_horizon_obstacles * a->max_speed + a->radius;
    const float range_sq = range * range;
    uint32_t count = 0;
    for (uint32_t k = 0; k < c->vertex_count; ++k) {
        const obst_vertex* o1 = &c->verts[k];
        const obst_vertex* o2 = &c->verts[o1->next];
        if (!(left_of(o1->point, o2->point, p) < 0.0f)) continue;
        const ak_vec2 e = sub(o2->point, o1->point);
        const float r = dot(sub(p, o1->point), e) / abs_sq(e);
        float d;
        if (r < 0.0f) d = abs_sq(sub(p, o1->point));
        else if (r > 1.0f) d = abs_sq(sub(p, o2->point));
        else d = abs_sq(sub(p, add(o1->point, mul(r, e))));
        if (!(d < range_sq)) continue;
        uint32_t i = count++;
        while (i > 0 && d < out[i - 1].dist_sq) {
            out[i] = out[i - 1];
            --i;
        }
        out[i].dist_sq = d;
        out[i].index = k;
    }
    return count;
}

/* The half-planes an obstacle edge puts on agent velocities (paper section 5.2), appended
 * to lines. */
static size_t obstacle_lines(const ak_crowd* c, ak_vec2 pos, ak_vec2 vel, const ak_crowd_agent* a,
                             const neigh* on, uint32_t on_count, ak_crowd_line* lines) {
    size_t nl = 0;
    const float inv_th = 1.0f / a->time_horizon_obstacles;
    const float radius = a->radius;
    for (uint32_t q = 0; q < on_count; ++q) {
        const obst_vertex* o1 = &c->verts[on[q].index];
        const obst_vertex* o2 = &c->verts[o1->next];
        const ak_vec2 rp1 = sub(o1->point, pos), rp2 = sub(o2->point, pos);
        /* An edge whose cut-off is already behind an earlier line adds nothing. */
        bool covered = false;
        for (size_t j = 0; j < nl; ++j)
            if (det(sub(mul(inv_th, rp1), lines[j].point), lines[j].direction) - inv_th * radius >= -EPS &&
                det(sub(mul(inv_th, rp2), lines[j].point), lines[j].direction) - inv_th * radius >= -EPS) {
                covered = true;
                break;
            }
        if (covered) continue;
        const float d1 = abs_sq(rp1), d2 = abs_sq(rp2), r2 = radius * radius;
        const ak_vec2 ov = sub(o2->point, o1->point);
        const float s = dot(neg(rp1), ov) / abs_sq(ov);
        const float dline = abs_sq(sub(neg(rp1), mul(s, ov)));
        ak_crowd_line line;
        /* Already colliding: push straight out. */
        if (s < 0.0f && d1 <= r2) {
            if (o1->convex) {
                line.point = v2(0.0f, 0.0f);
                line.direction = normalize(v2(-rp1.y, rp1.x));
                lines[nl++] = line;
            }
            continue;
        }
        if (s > 1.0f && d2 <= r2) {
            if (o2->convex && det(rp2, o2->direction) >= 0.0f) {
                line.point = v2(0.0f, 0.0f);
                line.direction = normalize(v2(-rp2.y, rp2.x));
                lines[nl++] = line;
            }
            continue;
        }
        if (s >= 0.0f && s <= 1.0f && dline <= r2) {
            line.point = v2(0.0f, 0.0f);
            line.direction = neg(o1->direction);
            lines[nl++] = line;
            continue;
        }
        /* Not colliding: the legs of the velocity obstacle (tangents from the agent's centre
         * to the discs of radius r around the edge's ends). */
        ak_vec2 left_leg, right_leg;
        const obst_vertex* e1 = o1;
        const obst_vertex* e2 = o2;
        if (s < 0.0f && dline <= r2) { /* seen end-on from o1's side: one vertex */
            if (!e1->convex) continue;
            e2 = e1;
            const float leg = sqrtf(d1 - r2);
            left_leg = divs(v2(rp1.x * leg - rp1.y * radius, rp1.x * radius + rp1.y * leg), d1);
            right_leg = divs(v2(rp1.x * leg + rp1.y * radius, -rp1.x * radius + rp1.y * leg), d1);
        } else if (s > 1.0f && dline <= r2) {
            if (!e2->convex) continue;
            e1 = e2;
            const float leg = sqrtf(d2 - r2);
            left_leg = divs(v2(rp2.x * leg - rp2.y * radius, rp2.x * radius + rp2.y * leg), d2);
            right_leg = divs(v2(rp2.x * leg + rp2.y * radius, -rp2.x * radius + rp2.y * leg), d2);
        } else {
            if (e1->convex) {
                const float leg = sqrtf(d1 - r2);
                left_leg = divs(v2(rp1.x * leg - rp1.y * radius, rp1.x * radius + rp1.y * leg), d1);
            } else {
                left_leg = neg(e1->direction);
            }
            if (e2->convex) {
                const float leg = sqrtf(d2 - r2);
                right_leg = divs(v2(rp2.x * leg + rp2.y * radius, -rp2.x * radius + rp2.y * leg), d2);
            } else {
                right_leg = e1->direction;
            }
        }
        /* A leg pointing into a neighbouring edge is replaced by that edge ("foreign"). */
        const obst_vertex* left_nb = &c->verts[e1->prev];
        bool left_foreign = false, right_foreign = false;
        if (e1->convex && det(left_leg, neg(left_nb->direction)) >= 0.0f) {
            left_leg = neg(left_nb->direction);
            left_foreign = true;
        }
        if (e2->convex && det(right_leg, e2->direction) <= 0.0f) {
            right_leg = e2->direction;
            right_foreign = true;
        }
        /* Project the velocity on the cut-off segment or a leg, whichever is nearest. */
        const ak_vec2 lc = mul(inv_th, sub(e1->point, pos));
        const ak_vec2 rc = mul(inv_th, sub(e2->point, pos));
        const ak_vec2 cv = sub(rc, lc);
        const float t = e1 == e2 ? 0.5f : dot(sub(vel, lc), cv) / abs_sq(cv);
        const float tl = dot(sub(vel, lc), left_leg);
        const float tr = dot(sub(vel, rc), right_leg);
        if ((t < 0.0f && tl < 0.0f) || (e1 == e2 && tl < 0.0f && tr < 0.0f)) {
            const ak_vec2 w = normalize(sub(vel, lc)); /* the left cut-off circle */
            line.direction = v2(w.y, -w.x);
            line.point = add(lc, mul(radius * inv_th, w));
            lines[nl++] = line;
            continue;
        }
        if (t > 1.0f && tr < 0.0f) {
            const ak_vec2 w = normalize(sub(vel, rc)); /* the right cut-off circle */
            line.direction = v2(w.y, -w.x);
            line.point = add(rc, mul(radius * inv_th, w));
            lines[nl++] = line;
            continue;
        }
        const float dcut = (t < 0.0f || t > 1.0f || e1 == e2) ? INFINITY : abs_sq(sub(vel, add(lc, mul(t, cv))));
        const float dleft = tl < 0.0f ? INFINITY : abs_sq(sub(vel, add(lc, mul(tl, left_leg))));
        const float dright = tr < 0.0f ? INFINITY : abs_sq(sub(vel, add(rc, mul(tr, right_leg))));
        if (dcut <= dleft && dcut <= dright) {
            line.direction = neg(e1->direction);
            line.point = add(lc, mul(radius * inv_th, v2(-line.direction.y, line.direction.x)));
            lines[nl++] = line;
            continue;
        }
        if (dleft <= dright) {
            if (left_foreign) continue;
            line.direction = left_leg;
            line.point = add(lc, mul(radius * inv_th, v2(-line.direction.y, line.direction.x)));
            lines[nl++] = line;
            continue;
        }
        if (right_foreign) continue;
        line.direction = neg(right_leg);
        line.point = add(rc, mul(radius * inv_th, v2(-line.direction.y, line.direction.x)));
        lines[nl++] = line;
    }
    return nl;
}

/* The reciprocal half-plane for a neighbour (paper section 4): u is the smallest change of
 * relative velocity that leaves the truncated velocity obstacle; each agent takes half. */
static ak_crowd_line agent_line(ak_vec2 pos, ak_vec2 vel, float radius, ak_vec2 opos, ak_vec2 ovel, float oradius,
                                float inv_th, float dt, float tie) {
    const ak_vec2 rp = sub(opos, pos);
    const ak_vec2 rv = sub(vel, ovel);
    const float dsq = abs_sq(rp);
    const float cr = radius + oradius;
    const float cr2 = cr * cr;
    ak_crowd_line line;
    ak_vec2 u;
    if (dsq > cr2) {
        const ak_vec2 w = sub(rv, mul(inv_th, rp)); /* from the cut-off centre */
        const float wl2 = abs_sq(w);
        const float dp = dot(w, rp);
        if (dp < 0.0f && dp * dp > cr2 * wl2) { /* project on the cut-off circle */
            const float wl = sqrtf(wl2);
            const ak_vec2 uw = divs(w, wl);
            line.direction = v2(uw.y, -uw.x);
            u = mul(cr * inv_th - wl, uw);
        } else { /* project on a leg */
            const float leg = sqrtf(dsq - cr2);
            if (det(rp, w) > 0.0f)
                line.direction = divs(v2(rp.x * leg - rp.y * cr, rp.x * cr + rp.y * leg), dsq);
            else
                line.direction = neg(divs(v2(rp.x * leg + rp.y * cr, -rp.x * cr + rp.y * leg), dsq));
            u = sub(mul(dot(rv, line.direction), line.direction), rv);
        }
    } else { /* overlapping: resolve within one step */
        const float inv_dt = 1.0f / dt;
        const ak_vec2 w = sub(rv, mul(inv_dt, rp));
        const float wl = len(w);
        /* same point, same velocity: the lower index moves toward +x, the other toward -x */
        const ak_vec2 uw = wl > 0.0f ? divs(w, wl) : v2(tie, 0.0f);
        line.direction = v2(uw.y, -uw.x);
        u = mul(cr * inv_dt - wl, uw);
    }
    line.point = add(vel, mul(0.5f, u));
    return line;
}

#if CROWD_SSE2
/* agent_line for four neighbours at once: every case computed in every lane and the lane's
 * own selected, each lane the same operations in the same order as agent_line (so the same
 * bits: SSE's add, mul, div and sqrt round as the scalar ones). */
static void agent_lines4(ak_vec2 pos, ak_vec2 vel, float radius, const ak_vec2* P, const ak_vec2* V, const float* R,
                         const uint64_t* keys, uint32_t self, float inv_th, float dt, ak_crowd_line* out) {
    const uint32_t j0 = nkey_index(keys[0]), j1 = nkey_index(keys[1]), j2 = nkey_index(keys[2]),
                   j3 = nkey_index(keys[3]);
    const __m128 opx = _mm_setr_ps(P[j0].x, P[j1].x, P[j2].x, P[j3].x);
    const __m128 opy = _mm_setr_ps(P[j0].y, P[j1].y, P[j2].y, P[j3].y);
    const __m128 ovx = _mm_setr_ps(V[j0].x, V[j1].x, V[j2].x, V[j3].x);
    const __m128 ovy = _mm_setr_ps(V[j0].y, V[j1].y, V[j2].y, V[j3].y);
    const __m128 orad = _mm_setr_ps(R[j0], R[j1], R[j2], R[j3]);
    const __m128 tie = _mm_setr_ps(self < j0 ? 1.0f : -1.0f, self < j1 ? 1.0f : -1.0f, self < j2 ? 1.0f : -1.0f,
                                   self < j3 ? 1.0f : -1.0f);
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    const __m128 sign = _mm_set1_ps(-0.0f); /* negation flips the sign bit, as the scalar's does */
    const __m128 rpx = _mm_sub_ps(opx, _mm_set1_ps(pos.x)), rpy = _mm_sub_ps(opy, _mm_set1_ps(pos.y));
    const __m128 vx = _mm_set1_ps(vel.x), vy = _mm_set1_ps(vel.y);
    const __m128 rvx = _mm_sub_ps(vx, ovx), rvy = _mm_sub_ps(vy, ovy);
    const __m128 dsq = _mm_add_ps(_mm_mul_ps(rpx, rpx), _mm_mul_ps(rpy, rpy));
    const __m128 cr = _mm_add_ps(_mm_set1_ps(radius), orad);
    const __m128 cr2 = _mm_mul_ps(cr, cr);
    const __m128 apart = _mm_cmpgt_ps(dsq, cr2);
    /* apart: w from the cut-off centre */
    const __m128 ith = _mm_set1_ps(inv_th);
    const __m128 wx = _mm_sub_ps(rvx, _mm_mul_ps(ith, rpx)), wy = _mm_sub_ps(rvy, _mm_mul_ps(ith, rpy));
    const __m128 wl2 = _mm_add_ps(_mm_mul_ps(wx, wx), _mm_mul_ps(wy, wy));
    const __m128 dp = _mm_add_ps(_mm_mul_ps(wx, rpx), _mm_mul_ps(wy, rpy));
    const __m128 cut = _mm_and_ps(_mm_cmplt_ps(dp, zero), _mm_cmpgt_ps(_mm_mul_ps(dp, dp), _mm_mul_ps(cr2, wl2)));
    /* the cut-off circle */
    const __m128 wl = _mm_sqrt_ps(wl2);
    const __m128 iwl = _mm_div_ps(one, wl);
    const __m128 cux = _mm_mul_ps(wx, iwl), cuy = _mm_mul_ps(wy, iwl);
    const __m128 cs = _mm_sub_ps(_mm_mul_ps(cr, ith), wl);
    const __m128 c_dx = cuy, c_dy = _mm_xor_ps(sign, cux);
    const __m128 c_ux = _mm_mul_ps(cs, cux), c_uy = _mm_mul_ps(cs, cuy);
    /* a leg */
    const __m128 leg = _mm_sqrt_ps(_mm_sub_ps(dsq, cr2));
    const __m128 idsq = _mm_div_ps(one, dsq);
    const __m128 left = _mm_cmpgt_ps(_mm_sub_ps(_mm_mul_ps(rpx, wy), _mm_mul_ps(rpy, wx)), zero);
    const __m128 llx = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(rpx, leg), _mm_mul_ps(rpy, cr)), idsq);
    const __m128 lly = _mm_mul_ps(_mm_add_ps(_mm_mul_ps(rpx, cr), _mm_mul_ps(rpy, leg)), idsq);
    const __m128 nrpx = _mm_xor_ps(sign, rpx);
    const __m128 rlx = _mm_xor_ps(sign, _mm_mul_ps(_mm_add_ps(_mm_mul_ps(rpx, leg), _mm_mul_ps(rpy, cr)), idsq));
    const __m128 rly = _mm_xor_ps(sign, _mm_mul_ps(_mm_add_ps(_mm_mul_ps(nrpx, cr), _mm_mul_ps(rpy, leg)), idsq));
    const __m128 l_dx = _mm_or_ps(_mm_and_ps(left, llx), _mm_andnot_ps(left, rlx));
    const __m128 l_dy = _mm_or_ps(_mm_and_ps(left, lly), _mm_andnot_ps(left, rly));
    const __m128 ld = _mm_add_ps(_mm_mul_ps(rvx, l_dx), _mm_mul_ps(rvy, l_dy));
    const __m128 l_ux = _mm_sub_ps(_mm_mul_ps(ld, l_dx), rvx), l_uy = _mm_sub_ps(_mm_mul_ps(ld, l_dy), rvy);
    /* overlapping: resolve within one step */
    const __m128 idt = _mm_set1_ps(1.0f / dt);
    const __m128 ox = _mm_sub_ps(rvx, _mm_mul_ps(idt, rpx)), oy = _mm_sub_ps(rvy, _mm_mul_ps(idt, rpy));
    const __m128 owl = _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(ox, ox), _mm_mul_ps(oy, oy)));
    const __m128 pos_wl = _mm_cmpgt_ps(owl, zero);
    const __m128 iowl = _mm_div_ps(one, owl);
    const __m128 oux = _mm_or_ps(_mm_and_ps(pos_wl, _mm_mul_ps(ox, iowl)), _mm_andnot_ps(pos_wl, tie));
    const __m128 ouy = _mm_and_ps(pos_wl, _mm_mul_ps(oy, iowl));
    const __m128 os = _mm_sub_ps(_mm_mul_ps(cr, idt), owl);
    const __m128 o_dx = ouy, o_dy = _mm_xor_ps(sign, oux);
    const __m128 o_ux = _mm_mul_ps(os, oux), o_uy = _mm_mul_ps(os, ouy);
    /* select: apart ? (cut ? cut-off : leg) : overlap */
#define SEL(m, a, b) _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b))
    const __m128 ac = _mm_and_ps(apart, cut);
    __m128 dx = SEL(apart, SEL(ac, c_dx, l_dx), o_dx), dy = SEL(apart, SEL(ac, c_dy, l_dy), o_dy);
    const __m128 ux = SEL(apart, SEL(ac, c_ux, l_ux), o_ux), uy = SEL(apart, SEL(ac, c_uy, l_uy), o_uy);
#undef SEL
    const __m128 half = _mm_set1_ps(0.5f);
    __m128 px = _mm_add_ps(vx, _mm_mul_ps(half, ux)), py = _mm_add_ps(vy, _mm_mul_ps(half, uy));
    _MM_TRANSPOSE4_PS(px, py, dx, dy);
    _mm_storeu_ps(&out[0].point.x, px);
    _mm_storeu_ps(&out[1].point.x, py);
    _mm_storeu_ps(&out[2].point.x, dx);
    _mm_storeu_ps(&out[3].point.x, dy);
}
#endif

static uint64_t mix64(uint64_t x) {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/* Below 1e-4 m/s in a direction drawn from (agent, step): breaks exact symmetries. */
static ak_vec2 perturb(const ak_crowd_step_job* job, size_t i, ak_vec2 v) {
    if (job->skip_perturbation) return v;
    const uint64_t h = mix64((uint64_t)i * 0x9e3779b97f4a7c15ull + mix64(job->step_index + 0x5851f42d4c957f2dull));
    const float angle = (float)(h >> 40) * (6.28318530717958647692f / 16777216.0f);
    const float mag = (float)((h >> 16) & 0xffffff) * (1e-4f / 16777216.0f);
    /* and a turn of 0.01 rad to the same side for every agent: a ring of agents that block
     * each other on the way to the centre (the circle's deadlock) then turns and unwinds */
    const float bias = 0.01f;
    return v2(v.x + mag * cosf(angle) + bias * v.y, v.y + mag * sinf(angle) - bias * v.x);
}

static ak_vec2 pref_velocity(const ak_crowd_step_job* job, const ak_crowd_agent* a, size_t i, ak_vec2 p) {
    if (job->pref_velocities.ptr) return perturb(job, i, job->pref_velocities.ptr[i]);
    uint32_t wp = job->waypoints.ptr[i];
    const uint32_t last = (uint32_t)a->goals.count - 1;
    if (wp > last) wp = last;
    while (wp < last && abs_sq(sub(a->goals.ptr[wp], p)) <= a->waypoint_radius * a->waypoint_radius) ++wp;
    job->waypoints.ptr[i] = wp;
    const ak_vec2 g = sub(a->goals.ptr[wp], p);
    const float s = a->pref_speed;
    if (wp < last || abs_sq(g) > s * s) return perturb(job, i, mul(s, normalize(g)));
    return perturb(job, i, g); /* within one second of the goal: arrive */
}

/* Keep to one side, as pedestrians do (unless skip_perturbation): while walking at full
 * speed (not on the last second to the goal), the preferred velocity turns SIDE_DRIFT to the
 * side the -0.01 rad turn of perturb takes ("right" below), and up to SIDE_TURN more, the
 * more the nearer, when a neighbour ahead heads toward the agent (its preferred velocity
 * against ours at half its speed or more) and is not already clearly on its right. Two
 * agents head-on both turn to their own right and pass on the left; in a corridor the two
 * directions sort into two lanes along the walls before they meet, instead of meeting
 * head-on across the whole width, where ORCA deadlocks (docs/crowd.md, "Jams"). Reads only
 * the step's inputs and every agent's preferred velocity (c->pref, computed before the
 * parallel pass): any thread count gives the same bits. */
#define SIDE_DRIFT 0.15f /* rad, while walking at full speed */
#define SIDE_TURN 0.35f  /* rad more, at most, for an oncoming neighbour */
static ak_vec2 keep_side(const ctx* c, const uint64_t* nb, uint32_t na, ak_vec2 p, const ak_crowd_agent* a,
                         ak_vec2 pref) {
    const ak_crowd_step_job* job = c->job;
    const float s2 = abs_sq(pref);
    /* only while walking at full speed (not when arriving: goal within a second) */
    if (job->skip_perturbation || !(s2 > 0.81f * a->pref_speed * a->pref_speed)) return pref;
    const float inv_s = 1.0f / sqrtf(s2);
    const ak_vec2 d = mul(inv_s, pref); /* unit heading wanted */
    float w = 0.0f;
    for (uint32_t k = 0; k < na; ++k) {
        const uint32_t j = nkey_index(nb[k]);
        const ak_vec2 rp = sub(job->positions.ptr[j], p);
        const float ahead = dot(rp, d);
        if (ahead <= 0.0f) continue;
        /* heading toward us at half its speed or more (not an agent settling on its goal) */
        if (dot(c->pref[j], d) > -0.5f * c->crowd->agents[j].pref_speed) continue;
        const float cr = a->radius + c->crowd->radii[j];
        if (det(d, rp) < -cr) continue; /* already clearly on our right: pass as it is */
        const float closeness = 1.0f - ahead / a->neighbor_distance;
        if (closeness > w) w = closeness;
    }
    const float t = SIDE_DRIFT + SIDE_TURN * w; /* small angles: rotate by -t */
    const float cs = 1.0f - 0.5f * t * t, sn = t - t * t * t * (1.0f / 6.0f);
    return v2(cs * pref.x + sn * pref.y, cs * pref.y - sn * pref.x);
}

/* All lines of agent i into w->lines; returns the count and the obstacle-line count. */
static size_t build_lines(const worker* w, size_t i, ak_vec2 p, ak_vec2 v, const ak_crowd_agent* a, size_t* out_obst) {
    const ctx* c = w->c;
    const ak_crowd_step_job* job = c->job;
    const uint32_t no = c->crowd->vertex_count ? obstacle_neighbors(c->crowd, p, a, w->obst_n) : 0;
    size_t nl = no ? obstacle_lines(c->crowd, p, v, a, w->obst_n, no, w->lines) : 0;
    *out_obst = nl;
    const uint32_t na = agent_neighbors(c, i, p, a, w->agent_n);
    const float inv_th = 1.0f / a->time_horizon;
    uint32_t k = 0;
#if CROWD_SSE2
    for (; k + 4 <= na; k += 4) {
        agent_lines4(p, v, a->radius, job->positions.ptr, job->velocities.ptr, c->crowd->radii, w->agent_n + k,
                     (uint32_t)i, inv_th, job->dt, w->lines + nl);
        nl += 4;
    }
#endif
    for (; k < na; ++k) {
        const uint32_t j = nkey_index(w->agent_n[k]);
        w->lines[nl++] = agent_line(p, v, a->radius, job->positions.ptr[j], job->velocities.ptr[j],
                                    c->crowd->radii[j], inv_th, job->dt, i < j ? 1.0f : -1.0f);
    }
    return nl;
}

/* Nearest ray hit t > 0 of o + t d (d unit) on a disc (centre q, radius r); INFINITY when
 * none. A ray starting inside the disc hits at t = 0. */
static float ray_disc(ak_vec2 o, ak_vec2 d, ak_vec2 q, float r) {
    const ak_vec2 m = sub(o, q);
    const float b = dot(m, d), cc = abs_sq(m) - r * r;
    if (cc <= 0.0f) return 0.0f;
    if (b > 0.0f) return INFINITY;
    const float disc = b * b - cc;
    if (disc < 0.0f) return INFINITY;
    return -b - sqrtf(disc);
}

/* Nearest hit of o + t d on segment a-b; INFINITY when none. */
static float ray_segment(ak_vec2 o, ak_vec2 d, ak_vec2 a, ak_vec2 b) {
    const ak_vec2 e = sub(b, a);
    const float den = det(d, e);
    if (fabsf(den) < 1e-12f) return INFINITY;
    const ak_vec2 ao = sub(a, o);
    const float t = det(ao, e) / den, u = det(ao, d) / den;
    return (t > 0.0f && u >= 0.0f && u <= 1.0f) ? t : INFINITY;
}

#define VISION_STAND_SPEED 0.25f /* m/s */
#define VISION_STAND_TTC 0.845f  /* s: 1 - exp(-0.5 t^2) = 0.3 */

/* Within a second of its last goal (pref_speed * 1 s), its own waypoints driving it: then the
 * preferred velocity is the offset to the goal per second (pref_velocity). */
static bool vision_arriving(const ak_crowd_step_job* job, const ak_crowd_agent* a, size_t i, ak_vec2 p) {
    if (job->pref_velocities.ptr) return false;
    const uint32_t last = (uint32_t)a->goals.count - 1;
    if (job->waypoints.ptr[i] < last) return false;
    return abs_sq(sub(a->goals.ptr[last], p)) <= a->pref_speed * a->pref_speed;
}

#if defined(__GNUC__) || defined(__clang__)
#define VISION_INLINE inline __attribute__((always_inline)) /* the ray cast's inner loop */
#else
#define VISION_INLINE inline
#endif

/* The turn and speed bounds gathered over a view's pixels. */
typedef struct vision_acc {
    float need_right, need_left; /* turn-rate bounds from the threats */
    bool right, left;
    float ttc_min;
    float tti_first;  /* the most imminent threat a turn can move (first in pixel order on a tie) */
    bool first_right; /* and its side: its bearing rate >= 0, cleared by turning right */
} vision_acc;

/* One pixel of the view: the visible object's point rp relative to the agent (along the unit
 * direction d), its velocity ovel, whether it is an agent. */
static VISION_INLINE void vision_pixel(vision_acc* acc, const ak_crowd_agent* a, ak_vec2 head, float speed, float pref_len,
                         ak_vec2 v, ak_vec2 d, ak_vec2 rp, ak_vec2 ovel, bool agent) {
    /* the pixel's point relative to the agent, and its relative velocity */
    const ak_vec2 rv = sub(ovel, v);
    const float dist2 = abs_sq(rp);
    const float closing = -dot(rp, rv); /* > 0 when approaching (times |rp|) */
    if (!(closing > 0.0f)) return;
    const float dist = sqrtf(dist2);
    /* time to interaction: to the point's closest approach (the threat test and the turn's
     * side); the speed reads the time to contact, until the point is one radius away along
     * the line of sight at the present closing speed (a point passing beside has its closest
     * approach now, but never touches) */
    const float tti = closing / abs_sq(rv);
    const float ttc = fmaxf(dist - a->radius, 0.0f) * dist / closing;
    const float rate = dist2 > 0.0f ? det(rp, rv) / dist2 : 0.0f; /* bearing rate, rad/s */
    const float thr = 0.6f * powf(fmaxf(tti, 1e-3f), -1.5f);
    if (fabsf(rate) >= thr) return; /* not a threat: it will pass */
    /* an agent standing or shuffling (under VISION_STAND_SPEED: parked, or jostled on its
     * place) slows the agent to 30% of pref_speed at most (ttc 0.845 s) and does not turn
     * it: it steps on through, and the contact projection shoulders both aside, as people
     * squeeze past those standing (a parked block is otherwise a wall the agent walks
     * along and never enters); a wall or a walker can stop it */
    const bool standing = agent && abs_sq(ovel) < VISION_STAND_SPEED * VISION_STAND_SPEED &&
                          dot(ovel, rp) >= -0.05f * dist;
    const float ttc_slow = standing ? fmaxf(ttc, VISION_STAND_TTC) : ttc;
    if (ttc_slow < acc->ttc_min) acc->ttc_min = ttc_slow;
    if (standing) return;
    /* Turning the heading by delta changes this bearing rate by about -k delta, with
     * k = (own speed) cos(angle to the point) / distance: keep the rate's sign and lift
     * it over the threshold (points beside or behind do not respond to a turn). */
    const float k = fmaxf(speed, 0.1f * pref_len) * dot(head, d) / dist;
    if (!(k > 1e-4f)) return;
    if (tti < acc->tti_first) acc->tti_first = tti, acc->first_right = rate >= 0.0f;
    if (rate >= 0.0f) {
        acc->right = true;
        acc->need_right = fminf(acc->need_right, (rate - thr) / k); /* delta <= this (< 0: clockwise) */
    } else {
        acc->left = true;
        acc->need_left = fmaxf(acc->need_left, (rate + thr) / k); /* delta >= this (> 0) */
    }
}

/* The heading the view looks along: the velocity, or the goal's direction when standing. */
static ak_vec2 vision_heading(ak_vec2 v, ak_vec2 pref) {
    const float speed = len(v), pref_len = len(pref);
    return speed > 1e-3f ? mul(1.0f / speed, v) : (pref_len > 0.0f ? mul(1.0f / pref_len, pref) : v2(1.0f, 0.0f));
}

/* RAYCAST: the ray from p along d against the na agent and no obstacle neighbours; returns the
 * nearest hit's distance (INFINITY: none), its velocity, whether an agent, its object id (an
 * agent's index, or agent_count + the edge's first vertex). */
static VISION_INLINE float vision_cast(const worker* w, ak_vec2 p, ak_vec2 d, uint32_t na, uint32_t no, ak_vec2* ovel, bool* agent,
                         uint32_t* object) {
    const ak_crowd* crowd = w->c->crowd;
    const ak_crowd_step_job* job = w->c->job;
    float best = INFINITY;
    *ovel = v2(0.0f, 0.0f);
    *agent = false;
    *object = UINT32_MAX;
    for (uint32_t q = 0; q < na; ++q) {
        const uint32_t j = nkey_index(w->agent_n[q]);
        const float t = ray_disc(p, d, job->positions.ptr[j], crowd->agents[j].radius);
        if (t < best) {
            best = t;
            *ovel = job->velocities.ptr[j];
            *agent = true;
            *object = j;
        }
    }
    for (uint32_t q = 0; q < no; ++q) {
        const obst_vertex* o1 = &crowd->verts[w->obst_n[q].index];
        const float t = ray_segment(p, d, o1->point, crowd->verts[o1->next].point);
        if (t < best) {
            best = t;
            *ovel = v2(0.0f, 0.0f);
            *agent = false;
            *object = (uint32_t)crowd->agent_count + w->obst_n[q].index;
        }
    }
    return best;
}

#define VISION_NEAR 0.1f /* m: the RASTER camera's near and far planes (depth error about 6e-8 z^2 / near per ulp) */
#define VISION_FAR 100.0f

/* Flat colour of view object id (1-based; 0 is the background): its 24 bits as bytes. */
static ak_vec4 vision_id_color(uint32_t id) {
    return ak_vec4_make((float)(id & 255u) / 255.0f, (float)((id >> 8) & 255u) / 255.0f,
                        (float)((id >> 16) & 255u) / 255.0f, 1.0f);
}

/* RASTER: render the view of the agent at p looking along head into vr (ids 1..na: the
 * agent neighbours in order, na + 1 ..: the obstacle neighbours); false when drawing failed. */
static bool vision_render(const worker* w, vision_raster* vr, ak_vec2 p, ak_vec2 head, uint32_t na, uint32_t no) {
    const ak_crowd* crowd = w->c->crowd;
    const ak_crowd_step_job* job = w->c->job;
    const uint32_t S = AK_CROWD_VISION_PRISM_SIDES;
    const float H = AK_CROWD_VISION_AGENT_HEIGHT, HW = AK_CROWD_VISION_WALL_HEIGHT;
    const float cs = cosf(3.14159265f / (float)S);
    ak_vec2 corner[AK_CROWD_VISION_PRISM_SIDES + 1]; /* the unit polygon's corners, the first again */
    ak_vec2 normal[AK_CROWD_VISION_PRISM_SIDES];     /* and its faces' outward normals */
    for (uint32_t m = 0; m <= S; ++m) {
        const float a = 6.28318531f * (float)(m % S) / (float)S, b = 6.28318531f * ((float)m + 0.5f) / (float)S;
        corner[m] = v2(cosf(a), sinf(a));
        if (m < S) normal[m] = v2(cosf(b), sinf(b));
    }
    size_t n = 0;
    for (uint32_t q = 0; q < na; ++q) {
        const uint32_t j = nkey_index(w->agent_n[q]);
        const ak_vec2 c = job->positions.ptr[j];
        const float R = crowd->agents[j].radius / cs; /* faces touch the disc */
        const ak_vec2 pc = sub(p, c);
        /* what the rasterizer would clip or cull anyway, left out before it: a prism wholly
         * behind the near plane, and the faces turned away from the eye */
        if (-dot(pc, head) + R < VISION_NEAR) continue;
        const ak_vec4 col = vision_id_color(q + 1);
        for (uint32_t m = 0; m < S; ++m) {
            if (!(dot(normal[m], pc) > crowd->agents[j].radius)) continue;
            const ak_vec3 b0 = ak_vec3_make(c.x + R * corner[m].x, 0.0f, c.y + R * corner[m].y);
            const ak_vec3 b1 = ak_vec3_make(c.x + R * corner[m + 1].x, 0.0f, c.y + R * corner[m + 1].y);
            const ak_vec3 t0 = ak_vec3_make(b0.x, H, b0.z), t1 = ak_vec3_make(b1.x, H, b1.z);
            /* counter-clockwise seen from outside */
            const ak_vec3 tri[6] = {b0, t1, b1, b0, t0, t1};
            for (int k = 0; k < 6; ++k) vr->pos[n + (size_t)k] = tri[k], vr->col[n + (size_t)k] = col;
            n += 6;
        }
    }
    for (uint32_t q = 0; q < no; ++q) {
        const obst_vertex* o1 = &crowd->verts[w->obst_n[q].index];
        const ak_vec2 a = o1->point, b = crowd->verts[o1->next].point;
        if (dot(sub(a, p), head) < VISION_NEAR && dot(sub(b, p), head) < VISION_NEAR) continue; /* behind */
        const ak_vec3 a0 = ak_vec3_make(a.x, 0.0f, a.y), b0 = ak_vec3_make(b.x, 0.0f, b.y);
        const ak_vec3 a1 = ak_vec3_make(a.x, HW, a.y), b1 = ak_vec3_make(b.x, HW, b.y);
        const ak_vec4 col = vision_id_color(na + q + 1);
        const ak_vec3 tri[12] = {a0, b0, b1, a0, b1, a1, a0, b1, b0, a0, a1, b1}; /* both sides */
        for (int k = 0; k < 12; ++k) vr->pos[n + (size_t)k] = tri[k], vr->col[n + (size_t)k] = col;
        n += 12;
    }
    const float vfov = AK_CROWD_VISION_VFOV * (3.14159265f / 180.0f);
    const ak_vec3 eye = ak_vec3_make(p.x, AK_CROWD_VISION_EYE_HEIGHT, p.y);
    const ak_vec3 at = ak_vec3_make(p.x + head.x, AK_CROWD_VISION_EYE_HEIGHT, p.y + head.y);
    const ak_raster_camera cam =
        ak_raster_camera_perspective(eye, at, vfov, vr->tan_half_fov / tanf(0.5f * vfov), VISION_NEAR, VISION_FAR);
    const ak_vec4 black = ak_vec4_make(0.0f, 0.0f, 0.0f, 1.0f);
    ak_raster_clear(vr->r, black, black);
    if (n) {
        ak_raster_mesh m = {.positions = {vr->pos, n}, .colors = {vr->col, n},
                            .material = {.color = {1.0f, 1.0f, 1.0f, 1.0f}},
                            .shading = AK_SHADING_UNLIT, .cull_back_faces = true};
        if (ak_raster_draw_mesh(vr->r, &cam, &m) != AK_OK) return false;
    }
    const size_t px = (size_t)crowd->vision_width * crowd->vision_height;
    return ak_raster_read_samples(vr->r, (ak_u8_span){vr->rgba, 4 * px}, (ak_f32_span){vr->depth, px}) == AK_OK;
}

/* RASTER: pixel (x, y)'s object (0: none; else its 1-based view id) and its point relative to
 * the agent (rp) and unit direction on the ground (d), from the depth. */
static uint32_t vision_raster_pixel(const ak_crowd* crowd, const vision_raster* vr, ak_vec2 head, uint32_t x, uint32_t y,
                                    ak_vec2* rp, ak_vec2* d) {
    const size_t i = (size_t)y * crowd->vision_width + x;
    const uint8_t* c = vr->rgba + 4 * i;
    const uint32_t id = (uint32_t)c[0] | (uint32_t)c[1] << 8 | (uint32_t)c[2] << 16;
    if (id == 0) return 0;
    const float n = VISION_NEAR, f = VISION_FAR;
    const float z = 2.0f * n * f / (f + n - (2.0f * vr->depth[i] - 1.0f) * (f - n)); /* along the heading */
    const float xn = 2.0f * ((float)x + 0.5f) / (float)crowd->vision_width - 1.0f;
    const float s = xn * vr->tan_half_fov;
    const ak_vec2 dir = v2(head.x - s * head.y, head.y + s * head.x); /* head + s * right */
    *rp = mul(z, dir);
    *d = mul(1.0f / sqrtf(abs_sq(dir)), dir);
    return id;
}

/* Synthetic-vision steering (Ondrej et al. 2010) for one agent: a view of vision_width
 * columns; per pixel the visible object's hit point, its time to interaction and the rate of
 * its bearing; the threats' bearing rates bound the turn rate and the nearest threat's time to
 * interaction sets the speed (the paper's two controls); the goal is a pixel kept in view. */
static ak_vec2 vision_velocity(const worker* w, size_t i, ak_vec2 p, ak_vec2 v, const ak_crowd_agent* a, ak_vec2 pref) {
    const ctx* c = w->c;
    const ak_crowd* crowd = c->crowd;
    const ak_crowd_step_job* job = c->job;
    /* Arrival (as ORCA's preferred velocity): within a second of its last goal pref is the
     * offset to the goal per second; the agent walks it, onto its place, unslowed and unturned
     * by the view: a neighbour in the way is pushed by the contact projection, and one pushed
     * off its place walks back at the same rule instead of freezing against its neighbours. */
    if (vision_arriving(job, a, i, p)) return pref;
    const uint32_t na = agent_neighbors(c, i, p, a, w->agent_n);
    const uint32_t no = crowd->vertex_count ? obstacle_neighbors(crowd, p, a, w->obst_n) : 0;
    const float speed = len(v);
    const float pref_len = len(pref);
    const ak_vec2 head = vision_heading(v, pref);
    const float theta = atan2f(head.y, head.x);
    const float fov = crowd->vision_fov;
    const uint32_t W = crowd->vision_width;
    vision_acc acc = {INFINITY, -INFINITY, false, false, INFINITY, INFINITY, false};
    if (crowd->vision_view == AK_CROWD_VIEW_RASTER) {
        if (vision_render(w, w->vr, p, head, na, no))
            for (uint32_t y = 0; y < crowd->vision_height; ++y)
                for (uint32_t x = 0; x < W; ++x) {
                    /* the pixel above with the same object and depth gives the same bounds */
                    const size_t px = (size_t)y * W + x;
                    if (y > 0 && memcmp(w->vr->rgba + 4 * px, w->vr->rgba + 4 * (px - W), 4) == 0 &&
                        memcmp(&w->vr->depth[px], &w->vr->depth[px - W], sizeof(float)) == 0)
                        continue;
                    ak_vec2 rp, d;
                    const uint32_t id = vision_raster_pixel(crowd, w->vr, head, x, y, &rp, &d);
                    if (id == 0 || id > na + no) continue;
                    const bool agent = id <= na;
                    const ak_vec2 ovel = agent ? job->velocities.ptr[nkey_index(w->agent_n[id - 1])] : v2(0.0f, 0.0f);
                    vision_pixel(&acc, a, head, speed, pref_len, v, d, rp, ovel, agent);
                }
    } else {
        for (uint32_t k = 0; k < W; ++k) {
            const float ang = theta + fov * (0.5f - ((float)k + 0.5f) / (float)W);
            const ak_vec2 d = v2(cosf(ang), sinf(ang));
            ak_vec2 ovel;
            bool agent;
            uint32_t object;
            const float best = vision_cast(w, p, d, na, no, &ovel, &agent, &object);
            if (!(best < INFINITY)) continue;
            vision_pixel(&acc, a, head, speed, pref_len, v, d, mul(best, d), ovel, agent);
        }
    }
    const float need_right = acc.need_right, need_left = acc.need_left, ttc_min = acc.ttc_min;
    const bool right = acc.right, left = acc.left;
    /* toward the goal, then the threats' bound on one side: with threats on both sides, the
     * side that keeps the passing side of the most imminent one */
    float delta = 0.0f, goal_bearing = 0.0f;
    if (pref_len > 0.0f) delta = goal_bearing = atan2f(det(head, pref), dot(head, pref));
    if (right && (!left || acc.first_right)) delta = fminf(delta, need_right);
    else if (left) delta = fmaxf(delta, need_left);
    /* the goal is a pixel kept in view: no turn takes it out of the field of view */
    if (pref_len > 0.0f) delta = ak_clampf(delta, goal_bearing - 0.5f * fov, goal_bearing + 0.5f * fov);
    const float max_turn = 3.0f * job->dt; /* 3 rad/s */
    const float turn = ak_clampf(delta, -max_turn, max_turn);
    const ak_vec2 nh = v2(head.x * cosf(turn) - head.y * sinf(turn), head.x * sinf(turn) + head.y * cosf(turn));
    float s = pref_len;
    if (ttc_min < INFINITY) s *= 1.0f - expf(-0.5f * ttc_min * ttc_min);
    /* a floor of 2 mm/s keeps the heading (the velocity's direction) of a stopped agent */
    s = fmaxf(fminf(s, a->max_speed), fminf(2e-3f, pref_len));
    return mul(s, nh);
}

static void* work(void* arg) {
    worker* w = (worker*)arg;
    const ctx* c = w->c;
    const ak_crowd_step_job* job = c->job;
    for (size_t s = w->begin; s < w->end; ++s) {
        const size_t i = c->cstart ? c->sidx[s] : s; /* in cell order: neighbours share the cache */
        const ak_crowd_agent* a = &c->crowd->agents[i];
        const ak_vec2 p = job->positions.ptr[i], v = job->velocities.ptr[i];
        const ak_vec2 pref = c->pref[i];
        if (c->crowd->method == AK_CROWD_VISION) {
            ak_vec2 nv = vision_velocity(w, i, p, v, a, pref);
            if (!ak_finitef(nv.x) || !ak_finitef(nv.y)) nv = v2(0.0f, 0.0f);
            job->out_velocities.ptr[i] = nv;
            job->out_positions.ptr[i] = add(p, mul(job->dt, nv));
            continue;
        }
        size_t no = 0;
        const size_t nl = build_lines(w, i, p, v, a, &no);
        const ak_vec2 want = keep_side(c, w->agent_n, (uint32_t)(nl - no), p, a, pref);
        ak_vec2 nv;
        const size_t fail = lp2(w->lines, nl, a->max_speed, want, false, &nv);
        if (fail < nl) lp3(w->lines, nl, no, fail, a->max_speed, w->proj, &nv);
        if (!ak_finitef(nv.x) || !ak_finitef(nv.y)) nv = v2(0.0f, 0.0f); /* never NaN out */
        job->out_velocities.ptr[i] = nv;
        job->out_positions.ptr[i] = add(p, mul(job->dt, nv));
    }
    return NULL;
}

/* Push an agent out of the obstacle edges it overlaps (from their outer side) to skin
 * beyond touching; *depth grows to the deepest penetration found. */
static ak_vec2 push_out_of_obstacles(const ak_crowd* crowd, ak_vec2 q, float r, float skin, float* depth) {
    for (uint32_t k = 0; k < crowd->vertex_count; ++k) {
        const obst_vertex* o1 = &crowd->verts[k];
        const ak_vec2 b = crowd->verts[o1->next].point;
        const ak_vec2 e = sub(b, o1->point);
        const float t = ak_clampf(dot(sub(q, o1->point), e) / abs_sq(e), 0.0f, 1.0f);
        const ak_vec2 d = sub(q, add(o1->point, mul(t, e)));
        const float d2 = abs_sq(d);
        if (d2 >= r * r || !(d2 > 0.0f) || left_of(o1->point, b, q) > 0.0f) continue;
        const float dl = sqrtf(d2);
        if (r - dl > *depth) *depth = r - dl;
        q = add(q, mul((r + skin - dl) / dl, d));
    }
    return q;
}

/* One Gauss-Seidel contact pass over every overlapping pair, in the grid's order (cells,
 * then the 9-cell stencil, then sorted entries: a function of the positions only), each pair
 * moved apart to skin beyond touching (omega times the overlap: 1 in RVO2's mode and the
 * projection's first passes, then its over-relaxation), then agents out of obstacle edges. Returns
 * the deepest overlap (pair or obstacle) the pass found, 0 when none. */
static float contact_pass(const ak_crowd* crowd, const ak_grid* g, ak_vec2* P, float skin, float omega) {
    float depth = 0.0f;
    for (uint32_t m = 0; m < g->cell_count; ++m) {
        const ak_grid_cell cm = g->cell_coord[m];
        for (int dz = -1; dz <= 1; ++dz)
            for (int dx = -1; dx <= 1; ++dx) {
                const ak_grid_cell cc = {cm.x + dx, 0, cm.z + dz};
                const uint32_t m2 = ak_grid_cell_find(g, cc);
                if (m2 == UINT32_MAX || m2 < m) continue;
                for (uint32_t s = g->cell_start[m]; s < g->cell_start[m + 1]; ++s) {
                    const uint32_t i = g->order[s];
                    for (uint32_t t = (m2 == m ? s + 1 : g->cell_start[m2]); t < g->cell_start[m2 + 1]; ++t) {
                        const uint32_t j = g->order[t];
                        const float rr = crowd->radii[i] + crowd->radii[j];
                        const ak_vec2 d = sub(P[i], P[j]);
                        const float d2 = abs_sq(d);
                        if (!(d2 < rr * rr)) continue;
                        const float dl = sqrtf(d2);
                        if (rr - dl > depth) depth = rr - dl;
                        /* coincident centres: split along x, lower index to -x */
                        const ak_vec2 dir = dl > 1e-6f * rr ? mul(1.0f / dl, d) : v2(i < j ? -1.0f : 1.0f, 0.0f);
                        const float hl = omega == 1.0f ? 0.5f * (rr + skin - dl) : 0.5f * (omega * (rr - dl) + skin);
                        const ak_vec2 h = mul(hl, dir);
                        P[i] = add(P[i], h);
                        P[j] = sub(P[j], h);
                    }
                }
            }
    }
    if (crowd->vertex_count)
        for (size_t i = 0; i < crowd->agent_count; ++i)
            P[i] = push_out_of_obstacles(crowd, P[i], crowd->agents[i].radius, skin, &depth);
    return depth;
}

/* The projection's candidates: every pair closer than its radii + CONTACT_MARGIN rmax and
 * every (agent, obstacle edge) closer than the radius + that margin, gathered in
 * contact_pass's order (grid cells, the 9-cell stencil, sorted entries; agents in index order
 * and edges in vertex order), and each agent's displacement since (an upper bound: the sum of
 * its moves). While no agent moved more than half the margin, no other pair or edge can
 * overlap, so passes over the lists do what contact_pass over a grid of the present positions
 * would, in a fixed order. */
typedef struct contact_set {
    uint32_t* pairs; /* [2 * pair_count] */
    size_t pair_count, pair_cap;
    uint32_t* edges; /* [2 * edge_count]: agent, vertex */
    size_t edge_count, edge_cap;
    float* moved;    /* [agent_count] */
    float margin;
} contact_set;

/* Gather the candidates (grid: cells of 2 rmax + margin over the present positions); false
 * when a list is full (the caller falls back to contact_pass). */
static bool contact_gather(const ak_crowd* crowd, const ak_grid* g, const ak_vec2* P, contact_set* s) {
    s->pair_count = s->edge_count = 0;
    const float m = s->margin;
    for (uint32_t c = 0; c < g->cell_count; ++c) {
        const ak_grid_cell cm = g->cell_coord[c];
        for (int dz = -1; dz <= 1; ++dz)
            for (int dx = -1; dx <= 1; ++dx) {
                const ak_grid_cell cc = {cm.x + dx, 0, cm.z + dz};
                const uint32_t c2 = ak_grid_cell_find(g, cc);
                if (c2 == UINT32_MAX || c2 < c) continue;
                for (uint32_t a = g->cell_start[c]; a < g->cell_start[c + 1]; ++a) {
                    const uint32_t i = g->order[a];
                    for (uint32_t b = (c2 == c ? a + 1 : g->cell_start[c2]); b < g->cell_start[c2 + 1]; ++b) {
                        const uint32_t j = g->order[b];
                        const float rr = crowd->radii[i] + crowd->radii[j] + m;
                        if (!(abs_sq(sub(P[i], P[j])) < rr * rr)) continue;
                        if (s->pair_count == s->pair_cap) return false;
                        s->pairs[2 * s->pair_count] = i;
                        s->pairs[2 * s->pair_count + 1] = j;
                        ++s->pair_count;
                    }
                }
            }
    }
    for (size_t i = 0; i < crowd->agent_count && crowd->vertex_count; ++i) {
        const float r = crowd->agents[i].radius + m;
        for (uint32_t k = 0; k < crowd->vertex_count; ++k) {
            const obst_vertex* o1 = &crowd->verts[k];
            const ak_vec2 e = sub(crowd->verts[o1->next].point, o1->point);
            const float t = ak_clampf(dot(sub(P[i], o1->point), e) / abs_sq(e), 0.0f, 1.0f);
            if (!(abs_sq(sub(P[i], add(o1->point, mul(t, e)))) < r * r)) continue;
            if (s->edge_count == s->edge_cap) return false;
            s->edges[2 * s->edge_count] = (uint32_t)i;
            s->edges[2 * s->edge_count + 1] = k;
            ++s->edge_count;
        }
    }
    memset(s->moved, 0, crowd->agent_count * sizeof *s->moved);
    return true;
}

/* Successive over-relaxation of the projection's pair moves: each overlapping pair is moved
 * apart by CONTACT_OVERRELAX times its overlap (plus the skin), i.e. to (CONTACT_OVERRELAX - 1)
 * times the overlap beyond touching. Plain Gauss-Seidel (1) splits every correction equally,
 * so a press against a wall (a pile of agents, each pushed toward the door by ORCA's
 * infeasible programs) relaxes like a long chain of equal masses: the 10,000-agent evacuation
 * hit the 1,024-pass cap on every step of its press with 0.1-0.4 mm left (-3.7 mm at worst);
 * over-relaxed, the same steps converge in 100-450 passes (docs/crowd.md, "Overlaps").
 * Only passes from the CONTACT_OVERRELAX_AFTER-th on are over-relaxed: the few passes of free
 * walking and light contact stay plain Gauss-Seidel (over-relaxing every pass left the
 * characters' planted feet of the 100-agent evacuation sliding 4.2 cm instead of 1.4 cm).
 * Obstacle edges are projected exactly (a wall does not move). */
#define CONTACT_OVERRELAX 1.9f
#define CONTACT_OVERRELAX_AFTER 32u

/* contact_pass over the gathered candidates (the same moves, in the gathered order, pairs
 * moved by omega times their overlap); returns the deepest overlap and sets *out_moved to the largest displacement
 * of an agent since the gather. */
static float contact_pass_set(const ak_crowd* crowd, contact_set* s, ak_vec2* P, float skin, float omega,
                              float* out_moved) {
    float depth = 0.0f, moved = 0.0f;
    for (size_t k = 0; k < s->pair_count; ++k) {
        const uint32_t i = s->pairs[2 * k], j = s->pairs[2 * k + 1];
        const float rr = crowd->radii[i] + crowd->radii[j];
        const ak_vec2 d = sub(P[i], P[j]);
        const float d2 = abs_sq(d);
        if (!(d2 < rr * rr)) continue;
        const float dl = sqrtf(d2);
        if (rr - dl > depth) depth = rr - dl;
        const ak_vec2 dir = dl > 1e-6f * rr ? mul(1.0f / dl, d) : v2(i < j ? -1.0f : 1.0f, 0.0f);
        const float hl = omega == 1.0f ? 0.5f * (rr + skin - dl) : 0.5f * (omega * (rr - dl) + skin);
        const ak_vec2 h = mul(hl, dir);
        P[i] = add(P[i], h);
        P[j] = sub(P[j], h);
        s->moved[i] += hl;
        s->moved[j] += hl;
        moved = ak_maxf(moved, ak_maxf(s->moved[i], s->moved[j]));
    }
    for (size_t k = 0; k < s->edge_count; ++k) {
        const uint32_t i = s->edges[2 * k];
        const obst_vertex* o1 = &crowd->verts[s->edges[2 * k + 1]];
        const ak_vec2 b = crowd->verts[o1->next].point, q = P[i];
        const float r = crowd->agents[i].radius;
        const ak_vec2 e = sub(b, o1->point);
        const float t = ak_clampf(dot(sub(q, o1->point), e) / abs_sq(e), 0.0f, 1.0f);
        const ak_vec2 d = sub(q, add(o1->point, mul(t, e)));
        const float d2 = abs_sq(d);
        if (d2 >= r * r || !(d2 > 0.0f) || left_of(o1->point, b, q) > 0.0f) continue;
        const float dl = sqrtf(d2);
        if (r - dl > depth) depth = r - dl;
        P[i] = add(q, mul((r + skin - dl) / dl, d));
        s->moved[i] += r + skin - dl;
        moved = ak_maxf(moved, s->moved[i]);
    }
    *out_moved = moved;
    return depth;
}

static void run_threads(void* (*fn)(void*), worker* w, uint32_t threads) {
    akp_run_tasks(fn, w, sizeof(worker), threads); /* the library's worker team (src/tasks.h) */
}

/* ---- scratch layout -------------------------------------------------------------------------- */

static uint32_t thread_total(const ak_crowd_step_job* job, size_t n) {
    uint32_t t = job->thread_count == 0 ? 1u : job->thread_count;
    if (t > 64) t = 64;
    if ((size_t)t * 256u > n) t = n / 256u > 0 ? (uint32_t)(n / 256u) : 1u; /* a thread start ~ 256 agents */
    return t;
}

/* Whether the step runs contact passes (their grid shares the scratch). */
static uint32_t contact_need(const ak_crowd_step_job* job) {
    return job->allow_overlap ? job->contact_iterations : 1u;
}

/* A VISION RASTER worker's buffers: the triangle soup, the samples read back. */
static void vision_raster_sizes(const ak_crowd* crowd, size_t* cap, size_t* s_pos, size_t* s_col, size_t* s_rgba,
                                size_t* s_depth) {
    *cap = (size_t)crowd->max_k * AK_CROWD_VISION_PRISM_SIDES * 6 + (size_t)crowd->vertex_count * 12;
    const size_t px = (size_t)crowd->vision_width * crowd->vision_height;
    *s_pos = akp_align16(*cap * sizeof(ak_vec3)), *s_col = akp_align16(*cap * sizeof(ak_vec4));
    *s_rgba = akp_align16(px * 4), *s_depth = akp_align16(px * sizeof(float));
}

/* Step scratch of one VISION RASTER worker: its render target (made in the scratch) and buffers
 * (0: the view's size is out of the rasterizer's range). */
static size_t vision_raster_bytes(const ak_crowd* crowd) {
    size_t cap, s_pos, s_col, s_rgba, s_depth;
    vision_raster_sizes(crowd, &cap, &s_pos, &s_col, &s_rgba, &s_depth);
    const ak_raster_desc rd = {.width = (int)crowd->vision_width, .height = (int)crowd->vision_height};
    const size_t target = ak_raster_memory_size(&rd);
    return target ? akp_align16(target) + 16 + s_pos + s_col + s_rgba + s_depth : 0;
}

typedef struct layout {
    size_t grid_pts, grid_mem, per_thread, contact, dense, dense_cap, pref, total;
    size_t raster; /* VISION RASTER: per thread, its render target and buffers (vision_raster) */
    size_t pair_cap, edge_cap; /* the projection's candidate lists (contact) */
    ak_grid_desc gd, contact_gd, gather_gd;
} layout;

/* The projection gathers candidate pairs closer than their radii + this (a fraction of the
 * largest radius) once, and gathers again only after some agent moved half of it. */
#define CONTACT_MARGIN 0.5f

static bool make_layout(const ak_crowd* c, size_t n, uint32_t threads, uint32_t contact_iterations, bool projection,
                        layout* L) {
    memset(L, 0, sizeof *L);
    L->gd.cell_size = c->cell_size;
    L->contact_gd.cell_size = ak_maxf(2.0f * c->max_radius, 1e-3f);
    L->gather_gd.cell_size = ak_maxf((2.0f + CONTACT_MARGIN) * c->max_radius, 1e-3f);
    /* the contact pass is Gauss-Seidel in the grid's cell order: keep the order it was tuned on */
    L->gd.cell_order = L->contact_gd.cell_order = L->gather_gd.cell_order = AK_GRID_ORDER_HASH;
    size_t gm = ak_grid_memory_size(n, &L->gd);
    if (contact_iterations > 0) {
        const size_t gm2 = ak_grid_memory_size(n, &L->contact_gd);
        if (gm2 > gm) gm = gm2;
    }
    if (projection) {
        const size_t gm3 = ak_grid_memory_size(n, &L->gather_gd);
        if (gm3 > gm) gm = gm3;
        L->pair_cap = 6 * n + 1024;
        L->edge_cap = c->vertex_count ? 2 * n + 1024 : 0;
        L->contact = akp_align16(L->pair_cap * 2 * sizeof(uint32_t)) + akp_align16(L->edge_cap * 2 * sizeof(uint32_t)) +
                     akp_align16(n * sizeof(float));
    }
    if (gm == 0 && n > 0) return false;
    L->grid_pts = akp_align16(n * sizeof(ak_vec3));
    L->grid_mem = akp_align16(gm);
    const size_t lines = (size_t)c->max_k + c->vertex_count;
    L->per_thread = akp_align16((size_t)c->max_k * sizeof(neigh)) + akp_align16((size_t)c->vertex_count * sizeof(neigh)) +
                    2 * akp_align16(lines * sizeof(ak_crowd_line));
    L->dense_cap = 4 * n + 1024;
    L->dense = dense_grid_bytes(n, L->dense_cap);
    L->pref = akp_align16(n * sizeof(ak_vec2));
    if (c->method == AK_CROWD_VISION && c->vision_view == AK_CROWD_VIEW_RASTER) {
        L->raster = vision_raster_bytes(c);
        if (L->raster == 0) return false;
    }
    L->total = L->grid_pts + L->grid_mem + L->contact + L->dense + L->pref +
               (size_t)threads * (L->per_thread + L->raster) + 16;
    return true;
}

static void carve_worker(const ak_crowd* c, char* base, worker* w) {
    const size_t lines = (size_t)c->max_k + c->vertex_count;
    w->agent_n = (uint64_t*)(void*)base;
    base += akp_align16((size_t)c->max_k * sizeof(neigh));
    w->obst_n = (neigh*)(void*)base;
    base += akp_align16((size_t)c->vertex_count * sizeof(neigh));
    w->lines = (ak_crowd_line*)(void*)base;
    base += akp_align16(lines * sizeof(ak_crowd_line));
    w->proj = (ak_crowd_line*)(void*)base;
}

/* The RASTER view's render targets and buffers, one per worker (AK_ERR_NO_MEMORY: none kept). */
static void vision_rasters_free(const ak_crowd* crowd, vision_raster* vr, uint32_t count) {
    const ak_allocator* al = crowd->alloc.alloc ? &crowd->alloc : NULL;
    for (uint32_t t = 0; t < count; ++t) {
        ak_raster_destroy(vr[t].r);
        if (vr[t].pos) akp_free(al, vr[t].pos);
        vr[t].r = NULL;
        vr[t].pos = NULL;
    }
}

static ak_result vision_rasters_make(const ak_crowd* crowd, vision_raster* vr, uint32_t count) {
    const ak_allocator* al = crowd->alloc.alloc ? &crowd->alloc : NULL;
    const size_t cap = (size_t)crowd->max_k * AK_CROWD_VISION_PRISM_SIDES * 6 + (size_t)crowd->vertex_count * 12;
    const size_t px = (size_t)crowd->vision_width * crowd->vision_height;
    const size_t s_pos = akp_align16(cap * sizeof(ak_vec3)), s_col = akp_align16(cap * sizeof(ak_vec4));
    const size_t s_rgba = akp_align16(px * 4), s_depth = akp_align16(px * sizeof(float));
    const ak_raster_desc rd = {.width = (int)crowd->vision_width, .height = (int)crowd->vision_height};
    memset(vr, 0, count * sizeof *vr);
    for (uint32_t t = 0; t < count; ++t) {
        char* mem = (char*)akp_alloc(al, s_pos + s_col + s_rgba + s_depth + 16);
        if (!mem || ak_raster_create(&rd, al, &vr[t].r) != AK_OK) {
            if (mem) akp_free(al, mem);
            vision_rasters_free(crowd, vr, count);
            return AK_ERR_NO_MEMORY;
        }
        vr[t].pos = (ak_vec3*)(void*)mem;
        vr[t].col = (ak_vec4*)(void*)(mem + s_pos);
        vr[t].rgba = (uint8_t*)(mem + s_pos + s_col);
        vr[t].depth = (float*)(void*)(mem + s_pos + s_col + s_rgba);
        vr[t].cap = cap;
        vr[t].tan_half_fov = tanf(0.5f * crowd->vision_fov);
    }
    return AK_OK;
}

/* An allocator over one block of step scratch: hands it out once (the render target's one
 * allocation); frees nothing. */
typedef struct scratch_arena {
    char* ptr;
    size_t left;
} scratch_arena;

static void* arena_alloc(size_t size, void* user) {
    scratch_arena* a = (scratch_arena*)user;
    if (size > a->left) return NULL;
    a->left = 0;
    return a->ptr;
}

static void arena_free(void* ptr, void* user) { (void)ptr, (void)user; }

/* The RASTER view's targets and buffers in the step scratch (mem: count blocks of
 * vision_raster_bytes, 16-byte aligned): no allocation per step. */
static ak_result vision_rasters_in_scratch(const ak_crowd* crowd, vision_raster* vr, uint32_t count, char* mem,
                                           size_t block) {
    size_t cap, s_pos, s_col, s_rgba, s_depth;
    vision_raster_sizes(crowd, &cap, &s_pos, &s_col, &s_rgba, &s_depth);
    const ak_raster_desc rd = {.width = (int)crowd->vision_width, .height = (int)crowd->vision_height};
    memset(vr, 0, count * sizeof *vr);
    for (uint32_t t = 0; t < count; ++t) {
        char* b = mem + (size_t)t * block;
        scratch_arena arena = {b, block - s_pos - s_col - s_rgba - s_depth};
        const ak_allocator al = {.alloc = arena_alloc, .free = arena_free, .user = &arena};
        if (ak_raster_create(&rd, &al, &vr[t].r) != AK_OK) return AK_ERR_BAD_ARG; /* the scratch is sized for it */
        char* buf = b + (block - s_pos - s_col - s_rgba - s_depth);
        vr[t].pos = (ak_vec3*)(void*)buf;
        vr[t].col = (ak_vec4*)(void*)(buf + s_pos);
        vr[t].rgba = (uint8_t*)(buf + s_pos + s_col);
        vr[t].depth = (float*)(void*)(buf + s_pos + s_col + s_rgba);
        vr[t].cap = cap;
        vr[t].tan_half_fov = tanf(0.5f * crowd->vision_fov);
    }
    return AK_OK;
}

static bool vision_raster_view(const ak_crowd* crowd) {
    return crowd->method == AK_CROWD_VISION && crowd->vision_view == AK_CROWD_VIEW_RASTER;
}

static char* align_up(void* p) { return (char*)(((uintptr_t)p + 15u) & ~(uintptr_t)15u); }

size_t ak_crowd_step_scratch_size(const ak_crowd_step_job* job) {
    if (!job || !job->crowd || job->thread_count > 64 || job->contact_iterations > 64) return 0;
    const size_t n = job->crowd->agent_count;
    layout L;
    if (!make_layout(job->crowd, n, thread_total(job, n), contact_need(job), !job->allow_overlap, &L)) return 0;
    return L.total;
}

static bool overlaps(const void* a, size_t an, const void* b, size_t bn) {
    const char *pa = (const char*)a, *pb = (const char*)b;
    if (!pa || !pb || an == 0 || bn == 0) return false;
    return pa < pb + bn && pb < pa + an;
}

ak_result ak_crowd_step_validate(const ak_crowd_step_job* job) {
    if (!job || !job->crowd || !job->positions.ptr || !job->velocities.ptr || !job->waypoints.ptr ||
        !job->out_positions.ptr || !job->out_velocities.ptr)
        return AK_ERR_NULL_ARG;
    if (!(job->dt > 0.0f) || !ak_finitef(job->dt) || job->thread_count > 64 || job->contact_iterations > 64)
        return AK_ERR_BAD_ARG;
    const size_t n = job->crowd->agent_count, b = n * sizeof(ak_vec2);
    const size_t ob = job->out_positions.count * sizeof(ak_vec2), ovb = job->out_velocities.count * sizeof(ak_vec2);
    if (overlaps(job->out_positions.ptr, ob, job->positions.ptr, b) ||
        overlaps(job->out_positions.ptr, ob, job->velocities.ptr, b) ||
        overlaps(job->out_velocities.ptr, ovb, job->positions.ptr, b) ||
        overlaps(job->out_velocities.ptr, ovb, job->velocities.ptr, b) ||
        overlaps(job->out_velocities.ptr, ovb, job->out_positions.ptr, ob) ||
        overlaps(job->waypoints.ptr, job->waypoints.count * sizeof(uint32_t), job->out_positions.ptr, ob) ||
        overlaps(job->waypoints.ptr, job->waypoints.count * sizeof(uint32_t), job->out_velocities.ptr, ovb) ||
        overlaps(job->scratch.ptr, job->scratch.count, job->out_positions.ptr, ob) ||
        overlaps(job->scratch.ptr, job->scratch.count, job->out_velocities.ptr, ovb))
        return AK_ERR_BAD_ARG;
    if (job->positions.count < n || job->velocities.count < n || job->waypoints.count < n ||
        job->out_positions.count < n || job->out_velocities.count < n ||
        (job->pref_velocities.ptr && job->pref_velocities.count < n))
        return AK_ERR_SPAN_SMALL;
    const size_t need = ak_crowd_step_scratch_size(job);
    if (need == 0 || job->scratch.count < need || !job->scratch.ptr) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i) {
        const ak_vec2 p = job->positions.ptr[i], v = job->velocities.ptr[i];
        if (!finite_in(p.x, COORD_MAX) || !finite_in(p.y, COORD_MAX) || !finite_in(v.x, COORD_MAX) ||
            !finite_in(v.y, COORD_MAX))
            return AK_ERR_BAD_DATA;
        if (job->pref_velocities.ptr) {
            const ak_vec2 q = job->pref_velocities.ptr[i];
            if (!finite_in(q.x, COORD_MAX) || !finite_in(q.y, COORD_MAX)) return AK_ERR_BAD_DATA;
        }
    }
    return AK_OK;
}

/* Build a grid over ground positions in the scratch; checks the budget. */
static ak_result build_grid(const ak_crowd_step_job* job, const layout* L, const ak_grid_desc* gd,
                            const ak_vec2* positions, char* base, ak_grid* grid) {
    const size_t n = job->crowd->agent_count;
    ak_vec3* pts = (ak_vec3*)(void*)base;
    for (size_t i = 0; i < n; ++i) pts[i] = ak_vec3_make(positions[i].x, 0.0f, positions[i].y);
    const ak_result r = ak_grid_build(gd, (ak_vec3_cspan){pts, n}, (ak_u8_span){(uint8_t*)(base + L->grid_pts), L->grid_mem}, grid);
    if (r != AK_OK) return r;
    uint64_t load = 0;
    for (uint32_t m = 0; m < grid->cell_count; ++m) {
        const uint64_t k = grid->cell_start[m + 1] - grid->cell_start[m];
        load += k * k;
    }
    const uint64_t budget = job->max_cell_load ? job->max_cell_load : AK_CROWD_DEFAULT_CELL_LOAD;
    return load > budget ? AK_ERR_BUDGET : AK_OK;
}

/* The neighbour search's grid: the dense one when it fits, else the shared hash grid; both
 * check the cell-load budget. */
static ak_result search_grid(ctx* c, const layout* L, char* base, ak_grid* grid) {
    const ak_crowd_step_job* job = c->job;
    uint64_t load = 0;
    if (dense_grid_build(c, job->positions.ptr, c->crowd->agent_count, c->crowd->cell_size,
                         base + L->grid_pts + L->grid_mem + L->contact, L->dense_cap, &load)) {
        const uint64_t budget = job->max_cell_load ? job->max_cell_load : AK_CROWD_DEFAULT_CELL_LOAD;
        return load > budget ? AK_ERR_BUDGET : AK_OK;
    }
    c->grid = grid;
    return build_grid(job, L, &L->gd, job->positions.ptr, base, grid);
}

ak_result ak_crowd_step_run(const ak_crowd_step_job* job) {
    const ak_result vr = ak_crowd_step_validate(job);
    if (vr != AK_OK) return vr;
    const ak_crowd* crowd = job->crowd;
    const size_t n = crowd->agent_count;
    const uint32_t threads = thread_total(job, n);
    layout L;
    make_layout(crowd, n, threads, contact_need(job), !job->allow_overlap, &L);
    char* base = align_up(job->scratch.ptr);
    ak_grid grid;
    ctx c = {.job = job, .crowd = crowd};
    const ak_result gr = search_grid(&c, &L, base, &grid);
    if (gr != AK_OK) return gr;
    /* every agent's preferred velocity first (keep_side reads the neighbours'), advancing
     * the waypoints in place */
    ak_vec2* pref = (ak_vec2*)(void*)(base + L.grid_pts + L.grid_mem + L.contact + L.dense);
    for (size_t i = 0; i < n; ++i) pref[i] = pref_velocity(job, &crowd->agents[i], i, job->positions.ptr[i]);
    c.pref = pref;
    worker w[64];
    vision_raster vrs[64];
    const bool raster = vision_raster_view(crowd);
    char* tb = base + L.grid_pts + L.grid_mem + L.contact + L.dense + L.pref;
    if (raster) { /* the render targets live in the step scratch, after the workers' */
        const ak_result mr = vision_rasters_in_scratch(crowd, vrs, threads, tb + (size_t)threads * L.per_thread, L.raster);
        if (mr != AK_OK) return mr;
    }
    for (uint32_t t = 0; t < threads; ++t) {
        w[t].c = &c;
        w[t].begin = n * t / threads;
        w[t].end = n * (t + 1) / threads;
        carve_worker(crowd, tb + (size_t)t * L.per_thread, &w[t]);
        w[t].vr = raster ? &vrs[t] : NULL;
    }
    run_threads(work, w, threads);
    if (job->allow_overlap) {
        /* RVO2's behaviour, with at most contact_iterations passes after it (0: pure ORCA) */
        for (uint32_t it = 0; it < job->contact_iterations; ++it) {
            const ak_result cr = build_grid(job, &L, &L.contact_gd, job->out_positions.ptr, base, &grid);
            if (cr != AK_OK) return cr;
            (void)contact_pass(crowd, &grid, job->out_positions.ptr, 0.0f, 1.0f);
        }
        return AK_OK;
    }
    /* The hard-contact projection: Gauss-Seidel passes (on this thread, the grid rebuilt for
     * each) until a pass finds no overlap deeper than AK_CROWD_CONTACT_TOLERANCE; pairs are
     * moved apart to a skin of a tenth of it beyond touching so that rounding does not leave
     * them overlapping. */
    const float tol = AK_CROWD_CONTACT_TOLERANCE;
    char* cb = base + L.grid_pts + L.grid_mem;
    contact_set set = {.pairs = (uint32_t*)(void*)cb, .pair_cap = L.pair_cap, .margin = CONTACT_MARGIN * crowd->max_radius};
    cb += akp_align16(L.pair_cap * 2 * sizeof(uint32_t));
    set.edges = (uint32_t*)(void*)cb;
    set.edge_cap = L.edge_cap;
    cb += akp_align16(L.edge_cap * 2 * sizeof(uint32_t));
    set.moved = (float*)(void*)cb;
    bool gathered = false;
    for (uint32_t it = 0; it < AK_CROWD_MAX_CONTACT_PASSES; ++it) {
        float depth;
        const float omega = it < CONTACT_OVERRELAX_AFTER ? 1.0f : CONTACT_OVERRELAX;
        if (!gathered) {
            /* (re)gather the candidates over the present positions; a full list -> this pass
             * the grid way */
            const ak_result cr = build_grid(job, &L, &L.gather_gd, job->out_positions.ptr, base, &grid);
            if (cr != AK_OK) return cr;
            gathered = contact_gather(crowd, &grid, job->out_positions.ptr, &set);
            if (!gathered) {
                const ak_result cr2 = build_grid(job, &L, &L.contact_gd, job->out_positions.ptr, base, &grid);
                if (cr2 != AK_OK) return cr2;
                depth = contact_pass(crowd, &grid, job->out_positions.ptr, 0.1f * tol, omega);
                if (!(depth > tol) && it + 1 >= job->contact_iterations) break;
                continue;
            }
        }
        float moved = 0.0f;
        depth = contact_pass_set(crowd, &set, job->out_positions.ptr, 0.1f * tol, omega, &moved);
        /* moved half the margin: a pair outside the lists may overlap now; gather again
         * before trusting a pass */
        const bool stale = !(moved < 0.5f * set.margin);
        if (!(depth > tol) && !stale && it + 1 >= job->contact_iterations) break;
        if (stale) gathered = false;
    }
    if (!job->orca_velocities) {
        /* the velocity the agent actually moved with */
        const float inv_dt = 1.0f / job->dt;
        for (size_t i = 0; i < n; ++i)
            job->out_velocities.ptr[i] = mul(inv_dt, sub(job->out_positions.ptr[i], job->positions.ptr[i]));
    }
    return AK_OK;
}

/* One agent's probe (ak_crowd_agent_lines, ak_crowd_agent_view): the step's layout over the job's
 * scratch, the neighbour search over every agent, and one worker's buffers. c, grid and w are the
 * caller's (w and c point into grid and the scratch). False when the search fails. */
static bool probe_worker(const ak_crowd_step_job* job, ctx* c, ak_grid* grid, worker* w) {
    const ak_crowd* crowd = job->crowd;
    layout L;
    make_layout(crowd, crowd->agent_count, thread_total(job, crowd->agent_count), contact_need(job), !job->allow_overlap, &L);
    char* base = align_up(job->scratch.ptr);
    *c = (ctx){.job = job, .crowd = crowd};
    if (search_grid(c, &L, base, grid) != AK_OK) return false;
    w->c = c;
    carve_worker(crowd, base + L.grid_pts + L.grid_mem + L.contact + L.dense + L.pref, w);
    return true;
}

size_t ak_crowd_agent_lines(const ak_crowd_step_job* job, size_t index, ak_crowd_line_span out_lines,
                            size_t* out_obstacle_line_count) {
    if (out_obstacle_line_count) *out_obstacle_line_count = 0;
    if (ak_crowd_step_validate(job) != AK_OK || index >= job->crowd->agent_count) return 0;
    const ak_crowd* crowd = job->crowd;
    ctx c;
    ak_grid grid;
    worker w;
    if (!probe_worker(job, &c, &grid, &w)) return 0;
    const ak_crowd_agent* a = &crowd->agents[index];
    size_t no = 0;
    const ak_vec2 p = job->positions.ptr[index], v = job->velocities.ptr[index];
    const size_t nl = build_lines(&w, index, p, v, a, &no);
    for (size_t k = 0; k < nl && k < out_lines.count && out_lines.ptr; ++k) out_lines.ptr[k] = w.lines[k];
    if (out_obstacle_line_count) *out_obstacle_line_count = no;
    return nl;
}

size_t ak_crowd_agent_view(const ak_crowd_step_job* job, size_t index, ak_u32_span out_object,
                           ak_f32_span out_distance) {
    if (ak_crowd_step_validate(job) != AK_OK || index >= job->crowd->agent_count) return 0;
    const ak_crowd* crowd = job->crowd;
    const uint32_t W = crowd->vision_width;
    if (crowd->method != AK_CROWD_VISION || (out_object.count && (!out_object.ptr || out_object.count < W)) ||
        (out_distance.count && (!out_distance.ptr || out_distance.count < W)))
        return 0;
    ctx c;
    ak_grid grid;
    worker w;
    if (!probe_worker(job, &c, &grid, &w)) return 0;
    /* the preferred velocity as the step computes it (this agent's only: the heading needs it) */
    const ak_vec2 p = job->positions.ptr[index], v = job->velocities.ptr[index];
    const ak_crowd_agent* a = &crowd->agents[index];
    uint32_t wp_saved = job->waypoints.ptr[index];
    const ak_vec2 pref = pref_velocity(job, a, index, p);
    job->waypoints.ptr[index] = wp_saved; /* a view changes no state */
    const uint32_t na = agent_neighbors(&c, index, p, a, w.agent_n);
    const uint32_t no = crowd->vertex_count ? obstacle_neighbors(crowd, p, a, w.obst_n) : 0;
    const ak_vec2 head = vision_heading(v, pref);
    for (uint32_t k = 0; k < W; ++k) {
        if (out_object.count) out_object.ptr[k] = UINT32_MAX;
        if (out_distance.count) out_distance.ptr[k] = INFINITY;
    }
    if (crowd->vision_view == AK_CROWD_VIEW_RASTER) {
        vision_raster vr;
        if (vision_rasters_make(crowd, &vr, 1) != AK_OK) return 0;
        w.vr = &vr;
        const bool ok = vision_render(&w, &vr, p, head, na, no);
        for (uint32_t y = 0; ok && y < crowd->vision_height; ++y)
            for (uint32_t x = 0; x < W; ++x) {
                ak_vec2 rp, d;
                const uint32_t id = vision_raster_pixel(crowd, &vr, head, x, y, &rp, &d);
                if (id == 0 || id > na + no) continue;
                const uint32_t k = W - 1 - x; /* image x grows to the agent's right; column 0 is its right */
                const float dist = len(rp);
                if (out_distance.count && !(dist < out_distance.ptr[k])) continue;
                if (out_distance.count) out_distance.ptr[k] = dist;
                if (out_object.count)
                    out_object.ptr[k] = id <= na ? nkey_index(w.agent_n[id - 1])
                                                 : (uint32_t)crowd->agent_count + w.obst_n[id - 1 - na].index;
            }
        vision_rasters_free(crowd, &vr, 1);
        return ok ? W : 0;
    }
    const float theta = atan2f(head.y, head.x);
    for (uint32_t k = 0; k < W; ++k) {
        const float ang = theta + crowd->vision_fov * (0.5f - ((float)k + 0.5f) / (float)W);
        const ak_vec2 d = v2(cosf(ang), sinf(ang));
        ak_vec2 ovel;
        bool agent;
        uint32_t object;
        const float best = vision_cast(&w, p, d, na, no, &ovel, &agent, &object);
        if (out_object.count) out_object.ptr[k] = object;
        if (out_distance.count) out_distance.ptr[k] = best;
    }
    return W;
}

/* ---- measures ------------------------------------------------------------------------------- */

typedef struct xkey {
    float x;
    uint32_t index;
} xkey;

static int xkey_cmp(const void* a, const void* b) {
    const xkey *p = (const xkey*)a, *q = (const xkey*)b;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    return p->index < q->index ? -1 : (p->index > q->index ? 1 : 0);
}

size_t ak_crowd_clearance_scratch_size(const ak_crowd* crowd, size_t count) {
    if (!crowd || count > AK_CROWD_MAX_AGENTS) return 0;
    ak_grid_desc gd = {.cell_size = ak_maxf(2.0f * crowd->max_radius, 1e-3f), .cell_order = AK_GRID_ORDER_HASH};
    return akp_align16(count * sizeof(ak_vec3)) + akp_align16(ak_grid_memory_size(count, &gd)) +
           akp_align16(count * sizeof(xkey)) + 16;
}

ak_result ak_crowd_clearance(const ak_crowd* crowd, ak_vec2_cspan positions, float overlap, ak_u8_span scratch,
                             float* out_min_distance, ak_u32_span out_pairs, size_t* out_overlap_count) {
    if (!crowd || !out_min_distance || (positions.count > 0 && !positions.ptr)) return AK_ERR_NULL_ARG;
    *out_min_distance = INFINITY;
    if (out_overlap_count) *out_overlap_count = 0;
    const size_t n = positions.count;
    if (n > crowd->agent_count) return AK_ERR_BAD_ARG;
    if (n < 2) return AK_OK;
    const size_t need = ak_crowd_clearance_scratch_size(crowd, n);
    if (!scratch.ptr || scratch.count < need) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i)
        if (!finite_in(positions.ptr[i].x, COORD_MAX) || !finite_in(positions.ptr[i].y, COORD_MAX)) return AK_ERR_BAD_DATA;
    ak_grid_desc gd = {.cell_size = ak_maxf(2.0f * crowd->max_radius, 1e-3f), .cell_order = AK_GRID_ORDER_HASH};
    char* base = align_up(scratch.ptr);
    ak_vec3* pts = (ak_vec3*)(void*)base;
    for (size_t i = 0; i < n; ++i) pts[i] = ak_vec3_make(positions.ptr[i].x, 0.0f, positions.ptr[i].y);
    ak_grid g;
    const size_t gm = akp_align16(ak_grid_memory_size(n, &gd));
    const ak_result r = ak_grid_build(&gd, (ak_vec3_cspan){pts, n},
                                      (ak_u8_span){(uint8_t*)(base + akp_align16(n * sizeof(ak_vec3))), gm}, &g);
    if (r != AK_OK) return r;
    uint64_t load = 0; /* agents stacked on a few points: the pair pass is quadratic */
    for (uint32_t m = 0; m < g.cell_count; ++m) {
        const uint64_t k = g.cell_start[m + 1] - g.cell_start[m];
        load += k * k;
    }
    if (load > AK_CROWD_DEFAULT_CELL_LOAD) return AK_ERR_BUDGET;
    /* Nearest pair within one cell of reach (radius sums <= the cell); pairs farther apart
     * only matter when no pair is that close, then a brute-force pass below decides. */
    double best = INFINITY;
    size_t over = 0;
    for (uint32_t m = 0; m < g.cell_count; ++m) {
        const ak_grid_cell cm = g.cell_coord[m];
        for (int dz = -1; dz <= 1; ++dz)
            for (int dx = -1; dx <= 1; ++dx) {
                const ak_grid_cell cc = {cm.x + dx, 0, cm.z + dz};
                const uint32_t m2 = ak_grid_cell_find(&g, cc);
                if (m2 == UINT32_MAX || m2 < m) continue;
                for (uint32_t s = g.cell_start[m]; s < g.cell_start[m + 1]; ++s) {
                    const uint32_t i = g.order[s];
                    for (uint32_t t = (m2 == m ? s + 1 : g.cell_start[m2]); t < g.cell_start[m2 + 1]; ++t) {
                        const uint32_t j = g.order[t];
                        const double ddx = (double)positions.ptr[i].x - positions.ptr[j].x;
                        const double ddz = (double)positions.ptr[i].y - positions.ptr[j].y;
                        const double d = sqrt(ddx * ddx + ddz * ddz) - crowd->agents[i].radius - crowd->agents[j].radius;
                        if (d < best) best = d;
                        if (d < -(double)overlap) {
                            if (out_pairs.ptr && 2 * over + 1 < out_pairs.count) {
                                out_pairs.ptr[2 * over] = i < j ? i : j;
                                out_pairs.ptr[2 * over + 1] = i < j ? j : i;
                            }
                            ++over;
                        }
                    }
                }
            }
    }
    if (!(best <= 0.0)) {
        /* No pair within reach: the minimum lies farther. Sort on x and sweep (exact; about
         * N log N for spread-out agents). */
        xkey* keys = (xkey*)(void*)(base + akp_align16(n * sizeof(ak_vec3)) + gm);
        for (size_t i = 0; i < n; ++i) keys[i] = (xkey){positions.ptr[i].x, (uint32_t)i};
        qsort(keys, n, sizeof *keys, xkey_cmp);
        const double rmax = crowd->max_radius;
        for (size_t a = 0; a < n; ++a) {
            const uint32_t i = keys[a].index;
            for (size_t b = a + 1; b < n; ++b) {
                const double gap = (double)keys[b].x - keys[a].x - crowd->agents[i].radius - rmax;
                if (gap >= best) break;
                const uint32_t j = keys[b].index;
                const double ddx = (double)positions.ptr[i].x - positions.ptr[j].x;
                const double ddz = (double)positions.ptr[i].y - positions.ptr[j].y;
                const double d = sqrt(ddx * ddx + ddz * ddz) - crowd->agents[i].radius - crowd->agents[j].radius;
                if (d < best) best = d;
            }
        }
    }
    *out_min_distance = (float)best;
    if (out_overlap_count) *out_overlap_count = over;
    return AK_OK;
}
