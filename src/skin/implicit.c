/* Implicit skinning (Vaillant et al. 2013, "Implicit Skinning: Real-Time Skin Deformation with
 * Contact Modeling"; 2014, "Robust Iso-Surface Tracking for Interactive Character Skinning").
 *
 * Precompute: segment by dominant joint, weld split vertices, build the welded one-ring
 * adjacency; per part, farthest-point samples with welded normals plus one cap sample per hole
 * (the hole's centre, normal pointing out of the part), a Hermite RBF fit (phi = r^3, linear
 * polynomial, solved in double by Gaussian elimination with partial pivoting on coordinates
 * normalised to the part), a support radius from the part's mean distance to its principal
 * axis; then every vertex's rest iso-value of the composed field.
 *
 * Per frame: DQS (the skinning job), then per welded vertex Newton steps along the composed
 * field's gradient towards the rest iso-value, stopping at gradient discontinuities, then
 * rounds of tangential relaxation (Jacobi: every vertex reads the previous round's positions,
 * so any thread split gives the same bits) and re-projection. */
#include <float.h>
#include <pthread.h> /* thread_count > 1 */

#include "skin_internal.h"
#include "../simd.h" /* AK_SIMD_SSE2: the trilinear interpolation 4 channels at a time */
#include "../tasks.h"

#define MAX_CAPS 16
#define STOP_COS 0.57357643635f /* cos 55 degrees: the 2014 paper's discontinuity angle */
#define ISO_EPS 1e-3f /* |F - iso| that ends a projection: about 0.1 % of the support radius */
#define UNCHECKED_EPS (16.0f * ISO_EPS) /* |F - iso| from which one Newton step is taken to
                                         converge when a later round checks it anyway */
#define CAPSULE_AT 12
#define GRID_AT (CAPSULE_AT + 8)
#define BONE_FLOATS (GRID_AT + 4) /* cx cy cz s | ax ay az b | r sphere2 valid pad |
                                     capsule a(3) b(3) radius pad | grid origin(3) 1/h, bind space */
#define GRID_INFO 4                /* per bone: nx ny nz, first node (0 0 0 0: no grid) */
#define GRID_MAX_NODES (1u << 23)  /* all grids together: 128 MiB at most */
#define PAIR_FLOATS 16 /* part i, part j, joint centre c(3), unit axes u_i(3) u_j(3) (from c into each
                          part), reach rho, seam radius, rest normal n(3) = unit(u_i - u_j); bind space */
#define BULGE_REACH 3.0f /* seam radii around a folded joint that swell to keep the volume */
#define CONTACT_FOLD 0.5f /* |R_i u_i + R_j u_j| beyond its rest value: about 30 degrees of bend */
#define CONTACT_SMOOTH 8 /* smoothing rounds of the contact region */
#define PAIR_FRAME 20 /* per joint and frame: posed centre (3), contact normal (3), folded flag, pad,
                        inner direction (3), pad, posed axis of part i (3), pad, of part j (3), pad */
#define CULL_FLOATS 8 /* per bone and frame: capsule end a(3), b - a (3), 1 / |b - a|^2, squared
                         distance from the segment past which the grid's field is 0 (0: no cull) */
#define BF_FLOATS 32 /* per bone and frame (bone_frames_build): posed point to grid coordinates (3x3
                        column-major, then translation), the capsule bound in grid units (end a(3),
                        b - a (3), 1 / |b - a|^2, squared reach; 0: no cull), the grid's upper
                        corner nx - 1, ny - 1, nz - 1, 1 / r, r, pad */
#define SAMPLE_FLOATS 8 /* x y z alpha | bx by bz pad (normalised coordinates) */
#define GROUP_FLOATS (24 * 4) /* a group of 4 bones: BF_FLOATS 0..23 of each, lane-interleaved */
#define GROUP_CAP 1024        /* groups per frame; cells beyond take the scalar loop */

struct ak_skin_implicit {
    ak_allocator alloc;
    size_t arrays_size; /* bytes of the arrays after the struct (the file's payload) */
    size_t vertex_count, triangle_count, joint_count, adj_count, sample_capacity, grid_nodes, pair_count;
    uint32_t influence_count;
    uint32_t closed;     /* 1: the welded mesh is closed (every edge in two triangles, opposite ways) */
    float rest_volume;   /* enclosed volume at the bind pose (closed meshes) */
    float step_cap; /* largest Newton step: half the mean support radius */
    float bulge;    /* contact bulge strength (0: plain union) */
    ak_vec3* positions;
    uint32_t* indices;
    uint16_t* joints;
    float* weights;
    uint16_t* part;
    float* iso;
    uint32_t* rep;       /* first vertex at the same bind position */
    uint32_t* adj_start; /* [vertex_count + 1], welded one-ring of representatives */
    uint32_t* adj;
    uint32_t* sample_start; /* [joint_count + 1] */
    float* samples;         /* [sample_capacity * SAMPLE_FLOATS] */
    float* bones;           /* [joint_count * BONE_FLOATS] */
    float* pairs;           /* [pair_count * PAIR_FLOATS]: parts that share a seam (a joint) */
    uint32_t* grid_info;    /* [joint_count * GRID_INFO] */
    float* grid;            /* [grid_nodes * 4]: HRBF distance d and grad d (bind space) per node;
                               the last array */
};

static size_t align64(size_t n) { return (n + 63u) & ~(size_t)63u; }

static inline unsigned ctz64(uint64_t v) {
#if defined(__GNUC__) || defined(__clang__)
    return (unsigned)__builtin_ctzll(v);
#else
    unsigned n = 0;
    while (!(v & 1u)) v >>= 1, ++n;
    return n;
#endif
}

#if AK_SIMD_SSE2
static inline uint32_t popcount64(uint64_t v) {
    uint32_t n = 0;
    for (; v; v &= v - 1) ++n;
    return n;
}
#endif

/* ---- object memory ----------------------------------------------------------------------- */

typedef struct implicit_counts {
    size_t vertex_count, triangle_count, joint_count, adj_count, sample_capacity;
    uint32_t influence_count;
    size_t grid_nodes, pair_count;
} implicit_counts;

static bool add_bytes(size_t* total, size_t count, size_t elem) {
    if (elem && count > (SIZE_MAX / 4) / elem) return false;
    size_t b = akp_align16(count * elem);
    if (*total > SIZE_MAX / 2 - b) return false;
    *total += b;
    return true;
}

static void* take(unsigned char** cur, size_t count, size_t elem) {
    void* p = *cur;
    *cur += akp_align16(count * elem);
    return p;
}

static ak_skin_implicit* object_alloc(const implicit_counts* c, const ak_allocator* alloc) {
    size_t total = akp_align16(sizeof(ak_skin_implicit));
    size_t nv = c->vertex_count, k = c->influence_count;
    bool ok = add_bytes(&total, nv, sizeof(ak_vec3)) && add_bytes(&total, 3 * c->triangle_count, 4) &&
              add_bytes(&total, nv * k, 2) && add_bytes(&total, nv * k, 4) && add_bytes(&total, nv, 2) &&
              add_bytes(&total, nv, 4) && add_bytes(&total, nv, 4) && add_bytes(&total, nv + 1, 4) &&
              add_bytes(&total, c->adj_count, 4) && add_bytes(&total, c->joint_count + 1, 4) &&
              add_bytes(&total, c->sample_capacity, SAMPLE_FLOATS * 4) &&
              add_bytes(&total, c->joint_count, BONE_FLOATS * 4) && add_bytes(&total, c->pair_count, PAIR_FLOATS * 4) &&
              add_bytes(&total, c->joint_count, GRID_INFO * 4) && add_bytes(&total, c->grid_nodes, 16);
    if (!ok) return NULL;
    unsigned char* mem = (unsigned char*)akp_alloc(alloc, total);
    if (!mem) return NULL;
    memset(mem, 0, total);
    ak_skin_implicit* o = (ak_skin_implicit*)(void*)mem;
    if (alloc) o->alloc = *alloc;
    o->vertex_count = nv, o->triangle_count = c->triangle_count, o->joint_count = c->joint_count;
    o->adj_count = c->adj_count, o->sample_capacity = c->sample_capacity, o->influence_count = c->influence_count;
    o->grid_nodes = c->grid_nodes, o->pair_count = c->pair_count;
    o->arrays_size = total - akp_align16(sizeof(ak_skin_implicit));
    unsigned char* cur = mem + akp_align16(sizeof(ak_skin_implicit));
    o->positions = (ak_vec3*)take(&cur, nv, sizeof(ak_vec3));
    o->indices = (uint32_t*)take(&cur, 3 * c->triangle_count, 4);
    o->joints = (uint16_t*)take(&cur, nv * k, 2);
    o->weights = (float*)take(&cur, nv * k, 4);
    o->part = (uint16_t*)take(&cur, nv, 2);
    o->iso = (float*)take(&cur, nv, 4);
    o->rep = (uint32_t*)take(&cur, nv, 4);
    o->adj_start = (uint32_t*)take(&cur, nv + 1, 4);
    o->adj = (uint32_t*)take(&cur, c->adj_count, 4);
    o->sample_start = (uint32_t*)take(&cur, c->joint_count + 1, 4);
    o->samples = (float*)take(&cur, c->sample_capacity, SAMPLE_FLOATS * 4);
    o->bones = (float*)take(&cur, c->joint_count, BONE_FLOATS * 4);
    o->pairs = (float*)take(&cur, c->pair_count, PAIR_FLOATS * 4);
    o->grid_info = (uint32_t*)take(&cur, c->joint_count, GRID_INFO * 4);
    o->grid = (float*)take(&cur, c->grid_nodes, 16);
    return o;
}

/* ---- the field ----------------------------------------------------------------------------- */

/* HRBF distance (world units) of bone b at bind-space point y, gradient to *g; false when y is
 * outside the bone's bounding sphere (the field is then 0). */
static bool bone_distance(const ak_skin_implicit* o, size_t b, ak_vec3 y, float* out_d, ak_vec3* out_g) {
    const float* B = o->bones + b * BONE_FLOATS;
    if (B[10] == 0.0f) return false;
    float inv_s = 1.0f / B[3];
    float qx = (y.x - B[0]) * inv_s, qy = (y.y - B[1]) * inv_s, qz = (y.z - B[2]) * inv_s;
    if (qx * qx + qy * qy + qz * qz > B[9]) return false;
    float d = B[4] * qx + B[5] * qy + B[6] * qz + B[7];
    float gx = B[4], gy = B[5], gz = B[6];
    const float* S = o->samples + (size_t)o->sample_start[b] * SAMPLE_FLOATS;
    const uint32_t n = o->sample_start[b + 1] - o->sample_start[b];
    for (uint32_t i = 0; i < n; ++i, S += SAMPLE_FLOATS) {
        float vx = qx - S[0], vy = qy - S[1], vz = qz - S[2];
        float r2 = vx * vx + vy * vy + vz * vz;
        float r = sqrtf(r2);
        float a = S[3], bx = S[4], by = S[5], bz = S[6];
        float vb = vx * bx + vy * by + vz * bz;
        /* alpha r^3 + 3 r (v . beta) */
        d += a * r2 * r + 3.0f * r * vb;
        /* alpha 3 r v + 3 (r beta + (v . beta) v / r) */
        float k1 = 3.0f * a * r + (r > 0.0f ? 3.0f * vb / r : 0.0f);
        float k2 = 3.0f * r;
        gx += k1 * vx + k2 * bx, gy += k1 * vy + k2 * by, gz += k1 * vz + k2 * bz;
    }
    d *= B[3];
    /* the HRBF of an open part extrapolates badly past its holes and far from its samples:
     * intersect it with a capsule around the part (the larger of the two distances) */
    {
        const float* K = B + CAPSULE_AT;
        ak_vec3 a = ak_vec3_make(K[0], K[1], K[2]), ab = ak_vec3_make(K[3] - K[0], K[4] - K[1], K[5] - K[2]);
        float l2 = ak_vec3_dot(ab, ab);
        float t = l2 > 0.0f ? ak_clampf(ak_vec3_dot(ak_vec3_sub(y, a), ab) / l2, 0.0f, 1.0f) : 0.0f;
        ak_vec3 w = ak_vec3_sub(y, ak_vec3_madd(a, ab, t));
        float wl = ak_vec3_length(w), dk = wl - K[6];
        if (dk > d && wl > 0.0f) d = dk, gx = w.x / wl, gy = w.y / wl, gz = w.z / wl;
    }
    *out_d = d;
    *out_g = ak_vec3_make(gx, gy, gz);
    return true;
}

/* Compact-support reparameterisation: t(u) = 1/2 - 15/16 (u - 2u^3/3 + u^5/5), u = d / r, of
 * distance d with gradient g (inv_r: 1 / the support radius r); the field's gradient to *out_g. */
static inline float compact(float inv_r, float d, ak_vec3 g, ak_vec3* out_g) {
    float u = d * inv_r;
    *out_g = ak_vec3_zero();
    if (!(u < 1.0f)) return 0.0f;
    if (u <= -1.0f) return 1.0f;
    float u2 = u * u;
    float t = 0.5f - 0.9375f * (u - u2 * u * (2.0f / 3.0f) + u2 * u2 * u * 0.2f);
    float dt = -0.9375f * (1.0f - u2) * (1.0f - u2) * inv_r;
    *out_g = ak_vec3_scale(g, dt);
    return t;
}

/* One bone's grid cell for a point: the first corner node, the strides, the fractions, and
 * for field_eval the support radius and the inverse palette matrix (NULL: bind pose). */
typedef struct grid_probe {
    const float* n000;
    const float* m;
    size_t sy, sz; /* floats */
    float tx, ty, tz, r; /* r: 1 / the support radius */
} grid_probe;

/* Whether a point at (ax, ay, az) from a capsule's start lies at least its radius from the
 * segment: c holds the segment's direction (3 floats, start to end), 1 / its squared length
 * and the squared radius. */
static inline bool beyond_capsule(float ax, float ay, float az, const float c[5]) {
    float t = (ax * c[0] + ay * c[1] + az * c[2]) * c[3];
    t = t > 0.0f ? (t < 1.0f ? t : 1.0f) : 0.0f;
    const float wx = ax - c[0] * t, wy = ay - c[1] * t, wz = az - c[2] * t;
    return wx * wx + wy * wy + wz * wz >= c[4];
}

/* The grid cell (grid info I: nodes per axis and first node) holding grid coordinates
 * (px, py, pz), inside the grid's box, into q's corner node, strides and fractions. */
static inline void cell_at(const ak_skin_implicit* o, const uint32_t* I, float px, float py, float pz, grid_probe* q) {
    const uint32_t nx = I[0], ny = I[1], nz = I[2];
    uint32_t ix = (uint32_t)px, iy = (uint32_t)py, iz = (uint32_t)pz;
    if (ix > nx - 2) ix = nx - 2;
    if (iy > ny - 2) iy = ny - 2;
    if (iz > nz - 2) iz = nz - 2;
    q->tx = px - (float)ix, q->ty = py - (float)iy, q->tz = pz - (float)iz;
    q->sy = 4 * (size_t)nx, q->sz = 4 * (size_t)nx * ny;
    q->n000 = o->grid + 4 * ((size_t)I[3] + ix + iy * (size_t)nx + iz * (size_t)nx * ny);
}

/* The cell of bone b's grid that holds bind-space point y into *q; false outside the grid's
 * box (the field is 0 there), and false as well where cull (CULL_FLOATS, or NULL) shows that
 * the interpolated distance is at least the support radius (the field is 0 there too;
 * cull_build). */
static inline bool grid_cell(const ak_skin_implicit* o, size_t b, ak_vec3 y, const float* cull, grid_probe* q) {
    const uint32_t* I = o->grid_info + b * GRID_INFO;
    const float* B = o->bones + b * BONE_FLOATS + GRID_AT;
    const uint32_t nx = I[0], ny = I[1], nz = I[2];
    float px = (y.x - B[0]) * B[3], py = (y.y - B[1]) * B[3], pz = (y.z - B[2]) * B[3];
    if (!(px >= 0.0f && py >= 0.0f && pz >= 0.0f && px <= (float)(nx - 1) && py <= (float)(ny - 1) &&
          pz <= (float)(nz - 1)) || nx < 2)
        return false;
    if (cull && cull[7] > 0.0f && beyond_capsule(y.x - cull[0], y.y - cull[1], y.z - cull[2], cull + 3)) return false;
    cell_at(o, I, px, py, pz, q);
    return true;
}

/* Trilinear interpolation of the 4 values per node (distance, gradient) of q's cell. The SSE2
 * path does per lane exactly the scalar loop's operations in the same order (lerp in x, then
 * y, then z; no fused multiply-add), so both give the same bits. */
static inline void grid_interp(const grid_probe* q, float r[4]) {
    const float *n000 = q->n000, *n010 = n000 + q->sy, *n001 = n000 + q->sz, *n011 = n001 + q->sy;
#if AK_SIMD_SSE2
    const __m128 tx = _mm_set1_ps(q->tx), ty = _mm_set1_ps(q->ty), tz = _mm_set1_ps(q->tz);
    const __m128 a0 = _mm_loadu_ps(n000), a1 = _mm_loadu_ps(n000 + 4), b0 = _mm_loadu_ps(n010), b1 = _mm_loadu_ps(n010 + 4);
    const __m128 c0 = _mm_loadu_ps(n001), c1 = _mm_loadu_ps(n001 + 4), d0 = _mm_loadu_ps(n011), d1 = _mm_loadu_ps(n011 + 4);
    const __m128 a = _mm_add_ps(a0, _mm_mul_ps(tx, _mm_sub_ps(a1, a0)));
    const __m128 bq = _mm_add_ps(b0, _mm_mul_ps(tx, _mm_sub_ps(b1, b0)));
    const __m128 cq = _mm_add_ps(c0, _mm_mul_ps(tx, _mm_sub_ps(c1, c0)));
    const __m128 dq = _mm_add_ps(d0, _mm_mul_ps(tx, _mm_sub_ps(d1, d0)));
    const __m128 e = _mm_add_ps(a, _mm_mul_ps(ty, _mm_sub_ps(bq, a))), f = _mm_add_ps(cq, _mm_mul_ps(ty, _mm_sub_ps(dq, cq)));
    _mm_storeu_ps(r, _mm_add_ps(e, _mm_mul_ps(tz, _mm_sub_ps(f, e))));
#else
    const float tx = q->tx, ty = q->ty, tz = q->tz;
    for (int k = 0; k < 4; ++k) {
        float a = n000[k] + tx * (n000[4 + k] - n000[k]);
        float bq = n010[k] + tx * (n010[4 + k] - n010[k]);
        float cq = n001[k] + tx * (n001[4 + k] - n001[k]);
        float dq = n011[k] + tx * (n011[4 + k] - n011[k]);
        float e = a + ty * (bq - a), f = cq + ty * (dq - cq);
        r[k] = e + tz * (f - e);
    }
#endif
}

/* Distance of bone b at bind-space point y and its gradient, from the bone's grid when the
 * object has grids (trilinear interpolation of the stored HRBF distance and gradient: the
 * paper's 3D textures), else directly; false outside the grid's box or the bounding sphere
 * (the field is 0 there). */
static bool bone_distance_fast(const ak_skin_implicit* o, size_t b, ak_vec3 y, float* out_d, ak_vec3* out_g) {
    if (o->grid_nodes == 0) return bone_distance(o, b, y, out_d, out_g);
    grid_probe q;
    if (!grid_cell(o, b, y, NULL, &q)) return false;
    float r[4];
    grid_interp(&q, r);
    *out_d = r[0];
    *out_g = ak_vec3_make(r[1], r[2], r[3]);
    return true;
}

/* The compact-support field of bone b from bone_distance_fast. */
static float bone_field_fast(const ak_skin_implicit* o, size_t b, ak_vec3 y, ak_vec3* out_g) {
    float d;
    ak_vec3 g;
    *out_g = ak_vec3_zero();
    if (!bone_distance_fast(o, b, y, &d, &g)) return 0.0f;
    return compact(1.0f / o->bones[b * BONE_FLOATS + 8], d, g, out_g);
}

/* Per-frame broad phase: a coarse grid over the posed boxes of the bones' fields, one bit per
 * bone per cell (set when the bone's posed box overlaps the cell); a point outside every box
 * has field 0. */
typedef struct broad_phase {
    float lo[3], inv_cell[3];
    uint32_t cells; /* per axis */
    size_t words;   /* 64-bit words per cell */
    uint64_t* mask; /* [cells^3 * words] */
    bool empty;
    /* SSE2, at most 64 bones: the bones of each distinct cell mask as groups of 4 (groups_build);
     * per cell its first group and count (count UINT32_MAX: no group, the scalar loop) */
    const uint32_t* cell_group; /* [2 * cells^3] or NULL */
    const float* group;         /* [GROUP_CAP * GROUP_FLOATS] */
    const uint32_t* group_bone; /* [GROUP_CAP * 4] */
} broad_phase;

/* Per-joint inverse transforms for one run: 12 floats (3x3 linear part column-major, then the
 * translation); identity when xf is NULL. */
typedef struct field_ctx {
    const ak_skin_implicit* o;
    const float* inv; /* [joint_count * 12] or NULL (bind pose) */
    float bulge;
    const broad_phase* bp; /* optional: skips bones whose box does not hold the point */
    const float* bf;       /* with bp: [joint_count * BF_FLOATS], bone_frames_build's records */
} field_ctx;

typedef struct field_acc {
    float f1, f2;
    ak_vec3 g1, g2;
} field_acc;

/* x (posed) into the bind space of a bone: the 3x4 column-major inverse palette matrix m. */
static inline ak_vec3 to_bone(const float* m, ak_vec3 x) {
    return ak_vec3_make(m[0] * x.x + m[3] * x.y + m[6] * x.z + m[9], m[1] * x.x + m[4] * x.y + m[7] * x.z + m[10],
                        m[2] * x.x + m[5] * x.y + m[8] * x.z + m[11]);
}

/* One bone's field f > 0 with its bind-space gradient gy into the two strongest, the gradient
 * taken to posed space: (M^-1)^T gy (m NULL: the bind pose). */
static inline void keep_strongest(field_acc* a, const float* m, float f, ak_vec3 gy) {
    const ak_vec3 g = m ? ak_vec3_make(m[0] * gy.x + m[1] * gy.y + m[2] * gy.z, m[3] * gy.x + m[4] * gy.y + m[5] * gy.z,
                                       m[6] * gy.x + m[7] * gy.y + m[8] * gy.z)
                        : gy;
    if (f > a->f1) {
        a->f2 = a->f1, a->g2 = a->g1;
        a->f1 = f, a->g1 = g;
    } else if (f > a->f2) {
        a->f2 = f, a->g2 = g;
    }
}

static inline void field_add(const field_ctx* c, size_t b, ak_vec3 x, field_acc* a) {
    const ak_skin_implicit* o = c->o;
    if (o->bones[b * BONE_FLOATS + 10] == 0.0f) return;
    const float* m = c->inv ? c->inv + 12 * b : NULL;
    const ak_vec3 y = m ? to_bone(m, x) : x;
    ak_vec3 gy;
    float f = bone_field_fast(o, b, y, &gy);
    if (f <= 0.0f) return;
    keep_strongest(a, m, f, gy);
}

static inline void prefetch_node(const float* p) {
#if defined(__GNUC__) || defined(__clang__)
    __builtin_prefetch(p);
    __builtin_prefetch(p + 7);
#else
    (void)p;
#endif
}

/* The cell of bone b's grid holding point x (posed) into *q, its nodes prefetched; false
 * where the field is 0 (grid_cell, with the capsule bound). Split from the interpolation so
 * that field_eval locates (and prefetches) every bone of a point before interpolating any. */
static inline bool grid_locate(const field_ctx* c, size_t b, ak_vec3 x, grid_probe* q) {
    const ak_skin_implicit* o = c->o;
    const float* F = c->bf + BF_FLOATS * b; /* the broad phase holds bones with grids only */
    const float px = F[0] * x.x + F[3] * x.y + F[6] * x.z + F[9];
    const float py = F[1] * x.x + F[4] * x.y + F[7] * x.z + F[10];
    const float pz = F[2] * x.x + F[5] * x.y + F[8] * x.z + F[11];
    if (!(px >= 0.0f && py >= 0.0f && pz >= 0.0f && px <= F[20] && py <= F[21] && pz <= F[22])) return false;
    if (F[19] > 0.0f && beyond_capsule(px - F[12], py - F[13], pz - F[14], F + 15)) return false;
    cell_at(o, o->grid_info + b * GRID_INFO, px, py, pz, q);
    q->m = c->inv + 12 * b;
    q->r = F[23];
    prefetch_node(q->n000);
    prefetch_node(q->n000 + q->sy);
    prefetch_node(q->n000 + q->sz);
    prefetch_node(q->n000 + q->sz + q->sy);
    return true;
}

#if AK_SIMD_SSE2
/* grid_locate for the 4 bones of group G at once (lanes in bone order; a padding lane fails its
 * box test): each lane does the scalar test's operations in the same order, so the same bones
 * pass with the same coordinates. Appends the located ones to probe[*n]. */
static inline void grid_locate4(const field_ctx* c, const float* G, const uint32_t* bones, ak_vec3 x, grid_probe* probe,
                                unsigned* n) {
    const __m128 X = _mm_set1_ps(x.x), Y = _mm_set1_ps(x.y), Z = _mm_set1_ps(x.z), zero = _mm_setzero_ps();
#define GQ(q) _mm_load_ps(G + 4 * (q))
    const __m128 px = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(GQ(0), X), _mm_mul_ps(GQ(3), Y)), _mm_mul_ps(GQ(6), Z)), GQ(9));
    const __m128 py = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(GQ(1), X), _mm_mul_ps(GQ(4), Y)), _mm_mul_ps(GQ(7), Z)), GQ(10));
    const __m128 pz = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(GQ(2), X), _mm_mul_ps(GQ(5), Y)), _mm_mul_ps(GQ(8), Z)), GQ(11));
    __m128 in = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(px, zero), _mm_cmpge_ps(py, zero)), _mm_cmpge_ps(pz, zero));
    in = _mm_and_ps(in, _mm_and_ps(_mm_and_ps(_mm_cmple_ps(px, GQ(20)), _mm_cmple_ps(py, GQ(21))), _mm_cmple_ps(pz, GQ(22))));
    if (!_mm_movemask_ps(in)) return;
    const __m128 ax = _mm_sub_ps(px, GQ(12)), ay = _mm_sub_ps(py, GQ(13)), az = _mm_sub_ps(pz, GQ(14));
    const __m128 t0 = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, GQ(15)), _mm_mul_ps(ay, GQ(16))), _mm_mul_ps(az, GQ(17))), GQ(18));
    const __m128 one = _mm_set1_ps(1.0f); /* t0 > 0 ? (t0 < 1 ? t0 : 1) : 0, as the scalar test */
    const __m128 t = _mm_and_ps(_mm_cmpgt_ps(t0, zero), akp_simd_select(_mm_cmplt_ps(t0, one), t0, one));
    const __m128 wx = _mm_sub_ps(ax, _mm_mul_ps(GQ(15), t)), wy = _mm_sub_ps(ay, _mm_mul_ps(GQ(16), t)),
                 wz = _mm_sub_ps(az, _mm_mul_ps(GQ(17), t));
    const __m128 w2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(wx, wx), _mm_mul_ps(wy, wy)), _mm_mul_ps(wz, wz));
    const __m128 culled = _mm_and_ps(_mm_cmpgt_ps(GQ(19), zero), _mm_cmpge_ps(w2, GQ(19)));
    int bits = _mm_movemask_ps(_mm_andnot_ps(culled, in));
#undef GQ
    if (!bits) return;
    float lx[4], ly[4], lz[4];
    _mm_storeu_ps(lx, px), _mm_storeu_ps(ly, py), _mm_storeu_ps(lz, pz);
    const ak_skin_implicit* o = c->o;
    for (; bits; bits &= bits - 1) {
        const unsigned l = (unsigned)ctz64((uint64_t)bits);
        const size_t b = bones[l];
        grid_probe* q = &probe[(*n)++];
        const uint32_t* I = o->grid_info + b * GRID_INFO;
        const uint32_t nx = I[0], ny = I[1], nz = I[2];
        uint32_t ix = (uint32_t)lx[l], iy = (uint32_t)ly[l], iz = (uint32_t)lz[l];
        if (ix > nx - 2) ix = nx - 2;
        if (iy > ny - 2) iy = ny - 2;
        if (iz > nz - 2) iz = nz - 2;
        q->tx = lx[l] - (float)ix, q->ty = ly[l] - (float)iy, q->tz = lz[l] - (float)iz;
        q->sy = 4 * (size_t)nx, q->sz = 4 * (size_t)nx * ny;
        q->n000 = o->grid + 4 * ((size_t)I[3] + ix + iy * (size_t)nx + iz * (size_t)nx * ny);
        q->m = c->inv + 12 * b;
        q->r = G[4 * 23 + l];
        prefetch_node(q->n000);
        prefetch_node(q->n000 + q->sy);
        prefetch_node(q->n000 + q->sz);
        prefetch_node(q->n000 + q->sz + q->sy);
    }
}
#endif

/* The located cell's field (bone_field_fast's interpolation and compact map, then
 * field_add's gradient transform) into the two strongest. */
static inline void grid_apply(const grid_probe* q, field_acc* a) {
    float r[4];
    grid_interp(q, r);
    ak_vec3 gy;
    const float f = compact(q->r, r[0], ak_vec3_make(r[1], r[2], r[3]), &gy);
    if (f <= 0.0f) return;
    const float* m = q->m;
    keep_strongest(a, m, f, gy);
}

static float field_eval(const field_ctx* c, ak_vec3 x, ak_vec3* out_g) {
    const ak_skin_implicit* o = c->o;
    field_acc a = {0.0f, 0.0f, ak_vec3_zero(), ak_vec3_zero()};
    const broad_phase* bp = c->bp;
    if (bp) {
        float p[3] = {(x.x - bp->lo[0]) * bp->inv_cell[0], (x.y - bp->lo[1]) * bp->inv_cell[1],
                      (x.z - bp->lo[2]) * bp->inv_cell[2]};
        const float top = (float)bp->cells;
        if (bp->empty || !(p[0] >= 0.0f && p[1] >= 0.0f && p[2] >= 0.0f && p[0] < top && p[1] < top && p[2] < top)) {
            *out_g = ak_vec3_zero();
            return 0.0f;
        }
        size_t cell = (size_t)p[0] + bp->cells * ((size_t)p[1] + bp->cells * (size_t)p[2]);
        const uint64_t* mw = bp->mask + cell * bp->words;
        /* with grids (the broad phase exists only then): locate every bone's cell first (their
         * nodes load meanwhile), then interpolate, in the same bone order */
        grid_probe probe[16];
        unsigned n = 0;
#if AK_SIMD_SSE2
        const uint32_t* cg = bp->cell_group ? bp->cell_group + 2 * cell : NULL;
        if (cg && cg[1] != UINT32_MAX) {
            for (uint32_t g = cg[0]; g < cg[0] + cg[1]; ++g) {
                grid_locate4(c, bp->group + (size_t)g * GROUP_FLOATS, bp->group_bone + 4 * (size_t)g, x, probe, &n);
                if (n > 12) { /* room for the next group's 4 */
                    for (unsigned k = 0; k < n; ++k) grid_apply(&probe[k], &a);
                    n = 0;
                }
            }
            mw = NULL;
        }
#endif
        for (size_t w = 0; mw && w < bp->words; ++w)
            for (uint64_t bits = mw[w]; bits; bits &= bits - 1)
                if (grid_locate(c, 64 * w + (size_t)ctz64(bits), x, &probe[n]) && ++n == 16) {
                    for (unsigned k = 0; k < n; ++k) grid_apply(&probe[k], &a);
                    n = 0;
                }
        for (unsigned k = 0; k < n; ++k) grid_apply(&probe[k], &a);
    } else {
        for (size_t b = 0; b < o->joint_count; ++b) field_add(c, b, x, &a);
    }
    float F = a.f1;
    ak_vec3 G = a.g1;
    if (c->bulge > 0.0f && a.f2 > 0.0f) {
        float l1 = ak_vec3_length(a.g1), l2 = ak_vec3_length(a.g2);
        if (l1 > 0.0f && l2 > 0.0f) {
            float w = -ak_vec3_dot(a.g1, a.g2) / (l1 * l2);
            if (w > 0.0f) {
                F += c->bulge * w * a.f2 * a.f2;
                G = ak_vec3_add(G, ak_vec3_scale(a.g2, 2.0f * c->bulge * w * a.f2));
            }
        }
    }
    *out_g = G;
    return F;
}

/* ---- precompute ---------------------------------------------------------------------------- */

ak_skin_implicit_desc ak_skin_implicit_desc_resolved(const ak_skin_implicit_desc* desc) {
    ak_skin_implicit_desc d = {0};
    if (desc) d = *desc;
    if (d.samples_per_bone == 0) d.samples_per_bone = 48;
    if (d.support_scale == 0.0f) d.support_scale = 0.5f;
    if (d.thread_count == 0) d.thread_count = 2;
    if (d.bulge == 0.0f) d.bulge = 0.5f;
    if (d.grid_resolution == 0) d.grid_resolution = 40;
    return d;
}

uint64_t ak_skin_implicit_key(const ak_skin_implicit_desc* desc) {
    if (!desc) return 0;
    ak_skin_implicit_desc d = ak_skin_implicit_desc_resolved(desc);
    uint64_t h = 0xcbf29ce484222325ull;
    h = akp_fnv1a(h, "AKIS2", 5);
    if (d.positions.ptr) h = akp_fnv1a(h, d.positions.ptr, d.positions.count * sizeof(ak_vec3));
    if (d.indices.ptr) h = akp_fnv1a(h, d.indices.ptr, d.indices.count * sizeof(uint32_t));
    if (d.joints.ptr) h = akp_fnv1a(h, d.joints.ptr, d.joints.count * sizeof(uint16_t));
    if (d.weights.ptr) h = akp_fnv1a(h, d.weights.ptr, d.weights.count * sizeof(float));
    uint64_t jc = d.joint_count;
    h = akp_fnv1a(h, &d.influence_count, sizeof d.influence_count);
    h = akp_fnv1a(h, &jc, sizeof jc);
    h = akp_fnv1a(h, &d.samples_per_bone, sizeof d.samples_per_bone);
    h = akp_fnv1a(h, &d.support_scale, sizeof d.support_scale);
    h = akp_fnv1a(h, &d.bulge, sizeof d.bulge);
    h = akp_fnv1a(h, &d.grid_resolution, sizeof d.grid_resolution);
    return h;
}

/* Solve A x = b (n x n, row-major, overwritten) by Gaussian elimination with partial pivoting;
 * false when a pivot is negligible. */
static bool solve_dense(double* A, double* b, size_t n) {
    double scale = 0.0;
    for (size_t i = 0; i < n * n; ++i) scale = fmax(scale, fabs(A[i]));
    if (!(scale > 0.0)) return false;
    for (size_t c = 0; c < n; ++c) {
        size_t piv = c;
        for (size_t r = c + 1; r < n; ++r)
            if (fabs(A[r * n + c]) > fabs(A[piv * n + c])) piv = r;
        if (!(fabs(A[piv * n + c]) > 1e-13 * scale)) return false;
        if (piv != c) {
            for (size_t k = 0; k < n; ++k) {
                double t = A[c * n + k];
                A[c * n + k] = A[piv * n + k], A[piv * n + k] = t;
            }
            double t = b[c];
            b[c] = b[piv], b[piv] = t;
        }
        double inv = 1.0 / A[c * n + c];
        for (size_t r = c + 1; r < n; ++r) {
            double f = A[r * n + c] * inv;
            if (f == 0.0) continue;
            for (size_t k = c; k < n; ++k) A[r * n + k] -= f * A[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (size_t c = n; c-- > 0;) {
        double s = b[c];
        for (size_t k = c + 1; k < n; ++k) s -= A[c * n + k] * b[k];
        b[c] = s / A[c * n + c];
    }
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(b[i])) return false;
    return true;
}

typedef struct fit_shared {
    ak_skin_implicit* o;
    const ak_vec3* normals; /* welded unit normals */
    uint32_t spb;
    float support_scale;
    const uint32_t* part_start; /* representatives sorted by part: CSR over joints */
    const uint32_t* part_verts;
    uint32_t next_part; /* guarded by lock */
    pthread_mutex_t lock;
    bool oom;
} fit_shared;

/* Fit bone b's HRBF; leaves the bone invalid (no field) when it has too few vertices or the
 * system is singular. */
static void fit_bone(fit_shared* sh, size_t b, double* A, double* rhs, float* mind, double (*pts)[6]) {
    ak_skin_implicit* o = sh->o;
    const uint32_t* verts = sh->part_verts + sh->part_start[b];
    const size_t m = sh->part_start[b + 1] - sh->part_start[b];
    float* B = o->bones + b * BONE_FLOATS;
    if (m < 4) return;
    /* centroid and principal axis (power iteration on the covariance) */
    double c[3] = {0, 0, 0};
    for (size_t i = 0; i < m; ++i) {
        ak_vec3 p = o->positions[verts[i]];
        c[0] += p.x, c[1] += p.y, c[2] += p.z;
    }
    for (int k = 0; k < 3; ++k) c[k] /= (double)m;
    double C[9] = {0};
    for (size_t i = 0; i < m; ++i) {
        ak_vec3 p = o->positions[verts[i]];
        double d[3] = {p.x - c[0], p.y - c[1], p.z - c[2]};
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) C[3 * r + k] += d[r] * d[k];
    }
    double ax[3] = {1.0, 0.7, 0.3};
    for (int it = 0; it < 64; ++it) {
        double n[3] = {0, 0, 0};
        for (int r = 0; r < 3; ++r) n[r] = C[3 * r] * ax[0] + C[3 * r + 1] * ax[1] + C[3 * r + 2] * ax[2];
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(l > 0.0)) break;
        for (int r = 0; r < 3; ++r) ax[r] = n[r] / l;
    }
    double radius = 0.0, rms = 0.0;
    for (size_t i = 0; i < m; ++i) {
        ak_vec3 p = o->positions[verts[i]];
        double d[3] = {p.x - c[0], p.y - c[1], p.z - c[2]};
        double along = d[0] * ax[0] + d[1] * ax[1] + d[2] * ax[2];
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        radius += sqrt(fmax(0.0, d2 - along * along));
        rms += d2;
    }
    radius /= (double)m;
    rms = sqrt(rms / (double)m);
    double tmin = 0.0, tmax = 0.0, rmax = 0.0;
    for (size_t i = 0; i < m; ++i) {
        ak_vec3 p = o->positions[verts[i]];
        double d[3] = {p.x - c[0], p.y - c[1], p.z - c[2]};
        double along = d[0] * ax[0] + d[1] * ax[1] + d[2] * ax[2];
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        tmin = fmin(tmin, along), tmax = fmax(tmax, along);
        rmax = fmax(rmax, sqrt(fmax(0.0, d2 - along * along)));
    }
    if (!(radius > 1e-3 * rms)) radius = rms;
    if (!(radius > 0.0)) return;
    /* caps: one per neighbouring part, at the centre of the shared boundary */
    double cap_sum[MAX_CAPS][3];
    uint32_t cap_part[MAX_CAPS], cap_n[MAX_CAPS], caps = 0;
    for (size_t i = 0; i < m; ++i) {
        uint32_t v = verts[i];
        for (uint32_t e = o->adj_start[v]; e < o->adj_start[v + 1]; ++e) {
            uint32_t w = o->part[o->adj[e]];
            if (w == b) continue;
            uint32_t k = 0;
            while (k < caps && cap_part[k] != w) ++k;
            if (k == caps) {
                if (caps == MAX_CAPS) continue;
                cap_part[k] = w, cap_n[k] = 0, cap_sum[k][0] = cap_sum[k][1] = cap_sum[k][2] = 0.0;
                ++caps;
            }
            ak_vec3 p = o->positions[v];
            cap_sum[k][0] += p.x, cap_sum[k][1] += p.y, cap_sum[k][2] += p.z, ++cap_n[k];
        }
    }
    /* each cap is a small disk: its centre and six points at 0.6 of the hole's mean radius,
     * all with the cap's normal (the hole's centre minus the part's centroid) */
    size_t n = 0;
    const size_t cap_max = sh->spb / 3;
    for (uint32_t k = 0; k < caps && n + 7 <= cap_max; ++k) {
        double h[3], d[3];
        for (int q = 0; q < 3; ++q) h[q] = cap_sum[k][q] / cap_n[k], d[q] = h[q] - c[q];
        double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(l > 1e-6 * rms)) continue;
        for (int q = 0; q < 3; ++q) d[q] /= l;
        double hr = 0.0;
        for (size_t i = 0; i < m; ++i) {
            uint32_t v = verts[i];
            bool rim = false;
            for (uint32_t e = o->adj_start[v]; e < o->adj_start[v + 1] && !rim; ++e) rim = o->part[o->adj[e]] == cap_part[k];
            if (!rim) continue;
            ak_vec3 p = o->positions[v];
            double w[3] = {p.x - h[0], p.y - h[1], p.z - h[2]};
            double al = w[0] * d[0] + w[1] * d[1] + w[2] * d[2];
            hr += sqrt(fmax(0.0, w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - al * al));
        }
        hr /= cap_n[k];
        /* two unit vectors spanning the cap's plane */
        double t1[3] = {fabs(d[0]) < 0.9 ? 1.0 : 0.0, fabs(d[0]) < 0.9 ? 0.0 : 1.0, 0.0}, t2[3];
        double dp = t1[0] * d[0] + t1[1] * d[1] + t1[2] * d[2];
        for (int q = 0; q < 3; ++q) t1[q] -= dp * d[q];
        double tl = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
        for (int q = 0; q < 3; ++q) t1[q] /= tl;
        t2[0] = d[1] * t1[2] - d[2] * t1[1], t2[1] = d[2] * t1[0] - d[0] * t1[2], t2[2] = d[0] * t1[1] - d[1] * t1[0];
        for (int e = 0; e < 7; ++e) {
            double ang = 1.0471975511965976 * e, rr = e == 0 ? 0.0 : 0.6 * hr;
            for (int q = 0; q < 3; ++q) {
                pts[n][q] = h[q] + rr * (cos(ang) * t1[q] + sin(ang) * t2[q]);
                pts[n][3 + q] = d[q];
            }
            ++n;
        }
    }
    /* farthest-point samples of the part, starting from the vertex farthest from the centroid */
    size_t first = 0;
    double far = -1.0;
    for (size_t i = 0; i < m; ++i) {
        ak_vec3 p = o->positions[verts[i]];
        double d2 = (p.x - c[0]) * (p.x - c[0]) + (p.y - c[1]) * (p.y - c[1]) + (p.z - c[2]) * (p.z - c[2]);
        if (d2 > far) far = d2, first = i;
    }
    for (size_t i = 0; i < m; ++i) mind[i] = FLT_MAX;
    for (size_t i = 0; i < n; ++i) /* caps repel samples too */
        for (size_t j = 0; j < m; ++j) {
            ak_vec3 p = o->positions[verts[j]];
            float d2 = (float)((p.x - pts[i][0]) * (p.x - pts[i][0]) + (p.y - pts[i][1]) * (p.y - pts[i][1]) +
                               (p.z - pts[i][2]) * (p.z - pts[i][2]));
            if (d2 < mind[j]) mind[j] = d2;
        }
    const float min_sep2 = (float)(1e-4 * radius * radius);
    size_t pick = first;
    while (n < sh->spb) {
        ak_vec3 p = o->positions[verts[pick]], nn = sh->normals[verts[pick]];
        if (ak_vec3_length_sq(nn) > 0.5f) {
            pts[n][0] = p.x, pts[n][1] = p.y, pts[n][2] = p.z;
            pts[n][3] = nn.x, pts[n][4] = nn.y, pts[n][5] = nn.z;
            ++n;
        }
        mind[pick] = -1.0f;
        float best = -1.0f;
        for (size_t j = 0; j < m; ++j) {
            if (mind[j] < 0.0f) continue;
            ak_vec3 q = o->positions[verts[j]];
            float d2 = ak_vec3_length_sq(ak_vec3_sub(q, p));
            if (d2 < mind[j]) mind[j] = d2;
            if (mind[j] > best) best = mind[j], pick = j;
        }
        if (best < min_sep2) break;
    }
    if (n < 4) return;
    /* normalised coordinates: q = (x - c) / s */
    const double s = radius;
    for (size_t i = 0; i < n; ++i)
        for (int q = 0; q < 3; ++q) pts[i][q] = (pts[i][q] - c[q]) / s;
    const size_t N = 4 * n + 4;
    memset(A, 0, N * N * sizeof(double));
    memset(rhs, 0, N * sizeof(double));
    for (size_t j = 0; j < n; ++j) {
        double* r0 = A + (4 * j) * N;
        for (size_t i = 0; i < n; ++i) {
            double v[3] = {pts[j][0] - pts[i][0], pts[j][1] - pts[i][1], pts[j][2] - pts[i][2]};
            double r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            r0[4 * i] = r * r * r;
            for (int q = 0; q < 3; ++q) r0[4 * i + 1 + (size_t)q] = 3.0 * r * v[q];
            for (int q = 0; q < 3; ++q) {
                double* rq = A + (4 * j + 1 + (size_t)q) * N;
                rq[4 * i] = 3.0 * r * v[q];
                for (int k = 0; k < 3; ++k)
                    rq[4 * i + 1 + (size_t)k] = r > 0.0 ? 3.0 * ((q == k ? r : 0.0) + v[q] * v[k] / r) : 0.0;
            }
        }
        for (int q = 0; q < 3; ++q) r0[4 * n + (size_t)q] = pts[j][q];
        r0[4 * n + 3] = 1.0;
        for (int q = 0; q < 3; ++q) {
            A[(4 * j + 1 + (size_t)q) * N + 4 * n + (size_t)q] = 1.0;
            rhs[4 * j + 1 + (size_t)q] = pts[j][3 + q];
        }
    }
    /* side conditions: sum alpha = 0, sum (alpha x + beta) = 0 */
    for (size_t i = 0; i < n; ++i) {
        A[(4 * n) * N + 4 * i] = 1.0;
        for (int q = 0; q < 3; ++q) {
            A[(4 * n + 1 + (size_t)q) * N + 4 * i] = pts[i][q];
            A[(4 * n + 1 + (size_t)q) * N + 4 * i + 1 + (size_t)q] = 1.0;
        }
    }
    if (!solve_dense(A, rhs, N)) return;
    float* S = o->samples + (size_t)o->sample_start[b] * SAMPLE_FLOATS;
    if (n > (size_t)(o->sample_start[b + 1] - o->sample_start[b])) return;
    double reach = 0.0;
    for (size_t i = 0; i < n; ++i) {
        float* e = S + i * SAMPLE_FLOATS;
        e[0] = (float)pts[i][0], e[1] = (float)pts[i][1], e[2] = (float)pts[i][2];
        e[3] = (float)rhs[4 * i];
        e[4] = (float)rhs[4 * i + 1], e[5] = (float)rhs[4 * i + 2], e[6] = (float)rhs[4 * i + 3], e[7] = 0.0f;
        reach = fmax(reach, sqrt(pts[i][0] * pts[i][0] + pts[i][1] * pts[i][1] + pts[i][2] * pts[i][2]));
    }
    for (size_t i = n; i < (size_t)(o->sample_start[b + 1] - o->sample_start[b]); ++i)
        memset(S + i * SAMPLE_FLOATS, 0, SAMPLE_FLOATS * sizeof(float)); /* zero weight: no effect */
    const double support = sh->support_scale * radius;
    B[0] = (float)c[0], B[1] = (float)c[1], B[2] = (float)c[2], B[3] = (float)s;
    B[4] = (float)rhs[4 * n], B[5] = (float)rhs[4 * n + 1], B[6] = (float)rhs[4 * n + 2], B[7] = (float)rhs[4 * n + 3];
    B[8] = (float)support;
    double sph = reach + 1.5 * support / s;
    B[9] = (float)(sph * sph);
    B[10] = 1.0f;
    {
        float* K = B + CAPSULE_AT;
        /* hemispherical ends inside the part's extent, so that past a hole the part closes
         * round (the paper's capped HRBFs) and never reaches into the neighbour's side */
        double rk = rmax + 0.25 * support, t0 = tmin + 0.5 * rk, t1 = tmax - 0.5 * rk;
        if (t0 > t1) t0 = t1 = 0.5 * (tmin + tmax);
        for (int q = 0; q < 3; ++q) K[q] = (float)(c[q] + t0 * ax[q]), K[3 + q] = (float)(c[q] + t1 * ax[q]);
        K[6] = (float)rk;
    }
}

static void* fit_worker(void* arg) {
    fit_shared* sh = (fit_shared*)arg;
    const ak_skin_implicit* o = sh->o;
    size_t spb = sh->spb, N = 4 * spb + 4, maxm = 0;
    for (size_t b = 0; b < o->joint_count; ++b) {
        size_t m = sh->part_start[b + 1] - sh->part_start[b];
        if (m > maxm) maxm = m;
    }
    double* A = (double*)malloc(N * N * sizeof(double) + N * sizeof(double) + spb * 6 * sizeof(double));
    float* mind = (float*)malloc((maxm ? maxm : 1) * sizeof(float));
    if (!A || !mind) {
        free(A), free(mind);
        pthread_mutex_lock(&sh->lock);
        sh->oom = true;
        pthread_mutex_unlock(&sh->lock);
        return NULL;
    }
    double* rhs = A + N * N;
    double(*pts)[6] = (double(*)[6])(void*)(rhs + N);
    for (;;) {
        pthread_mutex_lock(&sh->lock);
        size_t b = sh->next_part++;
        pthread_mutex_unlock(&sh->lock);
        if (b >= o->joint_count) break;
        fit_bone(sh, b, A, rhs, mind, pts);
    }
    free(A), free(mind);
    return NULL;
}

/* The grid of bone b: its capsule's box grown by the capsule radius plus the support radius
 * (the field is 0 on and beyond its faces), clipped to the bone's bounding sphere; nodes every
 * h along each axis, res along the longest side. False when the bone has no field. */
static bool grid_box(const ak_skin_implicit* o, size_t b, uint32_t res, float lo[3], float* out_h, uint32_t n[3]) {
    const float* B = o->bones + b * BONE_FLOATS;
    if (B[10] == 0.0f) return false;
    const float* K = B + CAPSULE_AT;
    const float ext = K[6] + B[8], R = sqrtf(B[9]) * B[3];
    float hi[3], side = 0.0f;
    for (int q = 0; q < 3; ++q) {
        lo[q] = fmaxf(fminf(K[q], K[3 + q]) - ext, B[q] - R);
        hi[q] = fminf(fmaxf(K[q], K[3 + q]) + ext, B[q] + R);
        if (!(hi[q] > lo[q])) return false;
        side = fmaxf(side, hi[q] - lo[q]);
    }
    const float h = side / (float)(res - 1);
    if (!(h > 0.0f) || !ak_finitef(h)) return false;
    for (int q = 0; q < 3; ++q) {
        float c = ceilf((hi[q] - lo[q]) / h - 1e-3f);
        n[q] = (uint32_t)fmaxf(c, 1.0f) + 1u;
        if (n[q] > res + 1) n[q] = res + 1;
    }
    *out_h = h;
    return true;
}

typedef struct grid_task {
    ak_skin_implicit* o;
    uint32_t index, count;
} grid_task;

/* Task t fills the z-slices z = t, t + count, ... of every grid with the direct field. */
static void* grid_fill(void* arg) {
    const grid_task* t = (const grid_task*)arg;
    ak_skin_implicit* o = t->o;
    for (size_t b = 0; b < o->joint_count; ++b) {
        const uint32_t* I = o->grid_info + b * GRID_INFO;
        if (I[0] < 2) continue;
        const float* G = o->bones + b * BONE_FLOATS + GRID_AT;
        const float h = 1.0f / G[3];
        for (uint32_t z = t->index; z < I[2]; z += t->count)
            for (uint32_t y = 0; y < I[1]; ++y)
                for (uint32_t x = 0; x < I[0]; ++x) {
                    ak_vec3 p = ak_vec3_make(G[0] + (float)x * h, G[1] + (float)y * h, G[2] + (float)z * h), g;
                    float dist;
                    if (!bone_distance(o, b, p, &dist, &g)) /* outside the sphere: no field */
                        dist = o->bones[b * BONE_FLOATS + 8], g = ak_vec3_zero();
                    float* N = o->grid + 4 * ((size_t)I[3] + x + (size_t)I[0] * (y + (size_t)I[1] * z));
                    N[0] = dist, N[1] = g.x, N[2] = g.y, N[3] = g.z;
                }
    }
    return NULL;
}

/* Each joint (pair of parts sharing a seam): its centre (the mean of the seam's edge ends),
 * seam radius, each part's unit axis from the centre to the part's centroid, the rest normal of
 * the contact plane and the reach rho (3 seam radii) of the contact there. A pair whose parts
 * have no field is left inert (rho 0). */
static void fill_pairs(ak_skin_implicit* o) {
    for (size_t p = 0; p < o->pair_count; ++p) {
        float* P = o->pairs + p * PAIR_FLOATS;
        const uint32_t i = (uint32_t)P[0], j = (uint32_t)P[1];
        memset(P + 2, 0, (PAIR_FLOATS - 2) * sizeof(float));
        const float* Bi = o->bones + (size_t)i * BONE_FLOATS;
        const float* Bj = o->bones + (size_t)j * BONE_FLOATS;
        if (Bi[10] == 0.0f || Bj[10] == 0.0f) continue;
        double c[3] = {0, 0, 0};
        size_t n = 0;
        for (size_t v = 0; v < o->vertex_count; ++v) {
            if (o->rep[v] != v || (o->part[v] != i && o->part[v] != j)) continue;
            for (uint32_t e = o->adj_start[v]; e < o->adj_start[v + 1]; ++e) {
                uint32_t w = o->adj[e];
                if (o->part[w] == o->part[v] || (o->part[w] != i && o->part[w] != j)) continue;
                c[0] += o->positions[v].x, c[1] += o->positions[v].y, c[2] += o->positions[v].z, ++n;
                break;
            }
        }
        if (n == 0) continue;
        for (int q = 0; q < 3; ++q) c[q] /= (double)n;
        double hr = 0.0;
        for (size_t v = 0; v < o->vertex_count; ++v) {
            if (o->rep[v] != v || (o->part[v] != i && o->part[v] != j)) continue;
            for (uint32_t e = o->adj_start[v]; e < o->adj_start[v + 1]; ++e) {
                uint32_t w = o->adj[e];
                if (o->part[w] == o->part[v] || (o->part[w] != i && o->part[w] != j)) continue;
                ak_vec3 q = o->positions[v];
                hr += sqrt((q.x - c[0]) * (q.x - c[0]) + (q.y - c[1]) * (q.y - c[1]) + (q.z - c[2]) * (q.z - c[2]));
                break;
            }
        }
        hr /= (double)n;
        ak_vec3 cc = ak_vec3_make((float)c[0], (float)c[1], (float)c[2]);
        ak_vec3 ui = ak_vec3_sub(ak_vec3_make(Bi[0], Bi[1], Bi[2]), cc), uj = ak_vec3_sub(ak_vec3_make(Bj[0], Bj[1], Bj[2]), cc);
        float li = ak_vec3_length(ui), lj = ak_vec3_length(uj);
        if (!(li > 1e-6f * (float)hr) || !(lj > 1e-6f * (float)hr) || !(hr > 0.0)) continue;
        ui = ak_vec3_scale(ui, 1.0f / li), uj = ak_vec3_scale(uj, 1.0f / lj);
        ak_vec3 nr = ak_vec3_sub(ui, uj);
        float ln = ak_vec3_length(nr);
        if (!(ln > 1e-3f)) continue; /* both parts on one side of their seam: no hinge */
        nr = ak_vec3_scale(nr, 1.0f / ln);
        P[2] = cc.x, P[3] = cc.y, P[4] = cc.z;
        P[5] = ui.x, P[6] = ui.y, P[7] = ui.z, P[8] = uj.x, P[9] = uj.y, P[10] = uj.z;
        P[11] = (float)(10.0 * hr), P[12] = (float)hr;
        P[13] = nr.x, P[14] = nr.y, P[15] = nr.z;
    }
}

static int cmp_u64_implicit(const void* a, const void* b) {
    uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
    return (x > y) - (x < y);
}

static ak_result check_desc(const ak_skin_implicit_desc* d) {
    if (!d->positions.ptr || !d->indices.ptr || !d->joints.ptr || !d->weights.ptr) return AK_ERR_NULL_ARG;
    if (d->positions.count == 0 || d->indices.count == 0) return AK_ERR_EMPTY;
    if (d->influence_count == 0 || d->influence_count > AK_MAX_INFLUENCES || d->indices.count % 3 ||
        d->samples_per_bone < 8 || d->samples_per_bone > 256 || !(d->support_scale > 0.0f) ||
        !(d->support_scale <= 100.0f) || !(d->bulge <= 10.0f) ||
        (d->grid_resolution != UINT32_MAX && (d->grid_resolution < 8 || d->grid_resolution > 128)) ||
        d->joint_count == 0 || d->joint_count > 65535 || d->thread_count > 64)
        return AK_ERR_BAD_ARG;
    const size_t nv = d->positions.count;
    if (nv > (1u << 24) || d->indices.count / 3 > (1u << 26)) return AK_ERR_BUDGET;
    if (d->joints.count < nv * d->influence_count || d->weights.count < nv * d->influence_count)
        return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < d->indices.count; ++i)
        if (d->indices.ptr[i] >= nv) return AK_ERR_BAD_INDEX;
    for (size_t i = 0; i < nv; ++i)
        if (!ak_vec3_is_finite(d->positions.ptr[i])) return AK_ERR_BAD_DATA;
    size_t bad = 0;
    ak_result r = ak_skin_weights_validate(d->joints, d->weights, nv, d->influence_count, d->joint_count, 0.0f, &bad);
    return r;
}

ak_result ak_skin_implicit_create(const ak_skin_implicit_desc* desc, const ak_allocator* alloc,
                                  ak_skin_implicit** out_implicit) {
    if (out_implicit) *out_implicit = NULL;
    if (!desc || !out_implicit) return AK_ERR_NULL_ARG;
    if (alloc && (!alloc->alloc != !alloc->free)) return AK_ERR_BAD_ARG;
    ak_skin_implicit_desc d = ak_skin_implicit_desc_resolved(desc);
    ak_result r = check_desc(&d);
    if (r != AK_OK) return r;
    const size_t nv = d.positions.count, nt = d.indices.count / 3, k = d.influence_count, jc = d.joint_count;
    /* temporaries: welded normals, weld scratch, directed edge list, part CSR */
    size_t wsc = ak_normals_welded_scratch_count(nv);
    uint32_t* wscratch = (uint32_t*)malloc(wsc * sizeof(uint32_t));
    ak_vec3* normals = (ak_vec3*)malloc(nv * sizeof(ak_vec3));
    uint64_t* edges = (uint64_t*)malloc(6 * nt * sizeof(uint64_t));
    uint32_t* part_start = (uint32_t*)calloc(jc + 1, sizeof(uint32_t));
    uint32_t* part_verts = (uint32_t*)malloc(nv * sizeof(uint32_t));
    ak_skin_implicit* o = NULL;
    if (!wscratch || !normals || !edges || !part_start || !part_verts) {
        r = AK_ERR_NO_MEMORY;
        goto fail;
    }
    if ((r = ak_normals_compute_welded(d.positions, d.indices, (ak_u32_span){wscratch, wsc},
                                       (ak_vec3_span){normals, nv})) != AK_OK)
        goto fail;
    /* wscratch[0..nv) now holds each vertex's representative; welded edges between them */
    size_t ne = 0;
    for (size_t t = 0; t < nt; ++t)
        for (int e = 0; e < 3; ++e) {
            uint32_t a = wscratch[d.indices.ptr[3 * t + (size_t)e]];
            uint32_t b = wscratch[d.indices.ptr[3 * t + (size_t)((e + 1) % 3)]];
            if (a == b) continue;
            edges[ne++] = ((uint64_t)a << 32) | b;
            edges[ne++] = ((uint64_t)b << 32) | a;
        }
    qsort(edges, ne, sizeof(uint64_t), cmp_u64_implicit);
    size_t uniq = 0;
    for (size_t i = 0; i < ne; ++i)
        if (uniq == 0 || edges[i] != edges[uniq - 1]) edges[uniq++] = edges[i];
    /* parts: dominant joint per vertex (first of the largest weights) */
    implicit_counts cnt = {nv, nt, jc, uniq, 0, (uint32_t)k, 0, 0};
    /* count vertices per part to size the sample pool */
    uint16_t* parts = (uint16_t*)malloc(nv * sizeof(uint16_t));
    if (!parts) {
        r = AK_ERR_NO_MEMORY;
        goto fail;
    }
    for (size_t v = 0; v < nv; ++v) {
        const float* w = d.weights.ptr + v * k;
        const uint16_t* j = d.joints.ptr + v * k;
        size_t best = 0;
        for (size_t q = 1; q < k; ++q)
            if (w[q] > w[best]) best = q;
        parts[v] = j[best];
    }
    /* a welded group takes its representative's part */
    for (size_t v = 0; v < nv; ++v) parts[v] = parts[wscratch[v]];
    for (size_t v = 0; v < nv; ++v)
        if (wscratch[v] == v) ++part_start[parts[v] + 1];
    for (size_t b = 0; b < jc; ++b) {
        if (part_start[b + 1] >= 4) cnt.sample_capacity += d.samples_per_bone;
        part_start[b + 1] += part_start[b];
    }
    /* joints: pairs of parts that share an edge (keys part_i << 16 | part_j, i < j), and whether
     * the welded mesh is closed (each directed edge once, its reverse present) */
    uint64_t* pair_keys = (uint64_t*)malloc((uniq + 1) * sizeof(uint64_t));
    uint64_t* dir = (uint64_t*)malloc((3 * nt + 1) * sizeof(uint64_t));
    if (!pair_keys || !dir) {
        free(parts), free(pair_keys), free(dir);
        r = AK_ERR_NO_MEMORY;
        goto fail;
    }
    for (size_t i = 0; i < uniq; ++i) {
        uint32_t pa = parts[edges[i] >> 32], pb = parts[(uint32_t)edges[i]];
        if (pa < pb) pair_keys[cnt.pair_count++] = ((uint64_t)pa << 16) | pb;
    }
    qsort(pair_keys, cnt.pair_count, sizeof(uint64_t), cmp_u64_implicit);
    {
        size_t u = 0;
        for (size_t i = 0; i < cnt.pair_count; ++i)
            if (u == 0 || pair_keys[i] != pair_keys[u - 1]) pair_keys[u++] = pair_keys[i];
        cnt.pair_count = u;
    }
    bool closed = true;
    {
        size_t nd = 0;
        for (size_t t = 0; t < nt; ++t)
            for (int e = 0; e < 3; ++e) {
                uint32_t a = wscratch[d.indices.ptr[3 * t + (size_t)e]];
                uint32_t b = wscratch[d.indices.ptr[3 * t + (size_t)((e + 1) % 3)]];
                if (a == b) closed = false;
                dir[nd++] = ((uint64_t)a << 32) | b;
            }
        qsort(dir, nd, sizeof(uint64_t), cmp_u64_implicit);
        for (size_t i = 0; closed && i < nd; ++i) {
            if (i > 0 && dir[i] == dir[i - 1]) closed = false;
            uint64_t rev = (dir[i] << 32) | (dir[i] >> 32);
            size_t lo = 0, hi = nd;
            while (lo < hi) {
                size_t mid = (lo + hi) / 2;
                if (dir[mid] < rev) lo = mid + 1;
                else hi = mid;
            }
            if (lo == nd || dir[lo] != rev) closed = false;
        }
    }
    free(dir);
    o = object_alloc(&cnt, alloc);
    if (!o) {
        free(parts), free(pair_keys);
        r = AK_ERR_NO_MEMORY;
        goto fail;
    }
    o->closed = closed ? 1u : 0u;
    for (size_t i = 0; i < cnt.pair_count; ++i) {
        o->pairs[i * PAIR_FLOATS] = (float)(pair_keys[i] >> 16);
        o->pairs[i * PAIR_FLOATS + 1] = (float)(pair_keys[i] & 0xffffu);
    }
    free(pair_keys);
    memcpy(o->positions, d.positions.ptr, nv * sizeof(ak_vec3));
    memcpy(o->indices, d.indices.ptr, 3 * nt * sizeof(uint32_t));
    memcpy(o->joints, d.joints.ptr, nv * k * sizeof(uint16_t));
    memcpy(o->weights, d.weights.ptr, nv * k * sizeof(float));
    memcpy(o->part, parts, nv * sizeof(uint16_t));
    memcpy(o->rep, wscratch, nv * sizeof(uint32_t));
    free(parts);
    for (size_t i = 0; i < uniq; ++i) ++o->adj_start[(edges[i] >> 32) + 1];
    for (size_t v = 0; v < nv; ++v) o->adj_start[v + 1] += o->adj_start[v];
    for (size_t i = 0; i < uniq; ++i) o->adj[i] = (uint32_t)edges[i]; /* sorted by source */
    {
        uint32_t* fill = (uint32_t*)malloc((jc + 1) * sizeof(uint32_t));
        if (!fill) {
            r = AK_ERR_NO_MEMORY;
            goto fail;
        }
        memcpy(fill, part_start, (jc + 1) * sizeof(uint32_t));
        for (size_t v = 0; v < nv; ++v)
            if (o->rep[v] == v) part_verts[fill[o->part[v]]++] = (uint32_t)v;
        free(fill);
    }
    for (size_t b = 0, s = 0; b < jc; ++b) {
        o->sample_start[b] = (uint32_t)s;
        if (part_start[b + 1] - part_start[b] >= 4) s += d.samples_per_bone;
        o->sample_start[b + 1] = (uint32_t)s;
    }
    {
        fit_shared sh = {.o = o, .normals = normals, .spb = d.samples_per_bone, .support_scale = d.support_scale,
                         .part_start = part_start, .part_verts = part_verts};
        pthread_mutex_init(&sh.lock, NULL);
        pthread_t ids[64];
        bool started[64] = {false};
        uint32_t threads = d.thread_count;
        for (uint32_t t = 1; t < threads; ++t) started[t] = pthread_create(&ids[t], NULL, fit_worker, &sh) == 0;
        fit_worker(&sh);
        for (uint32_t t = 1; t < threads; ++t)
            if (started[t]) pthread_join(ids[t], NULL);
        pthread_mutex_destroy(&sh.lock);
        if (sh.oom) {
            r = AK_ERR_NO_MEMORY;
            goto fail;
        }
    }
    fill_pairs(o);
    if (o->closed)
        o->rest_volume = (float)ak_volume_compute((ak_vec3_cspan){o->positions, nv}, (ak_u32_cspan){o->indices, 3 * nt});
    if (!(o->rest_volume > 0.0f) || !ak_finitef(o->rest_volume)) o->closed = 0, o->rest_volume = 0.0f;
    if (d.grid_resolution != UINT32_MAX) {
        /* sample every part's field on its grid: a second object with the grids appended (the
         * arrays before them keep their layout, so one copy moves them) */
        cnt.grid_nodes = 0;
        for (size_t b = 0; b < jc; ++b) {
            float lo[3], h;
            uint32_t n[3];
            if (!grid_box(o, b, d.grid_resolution, lo, &h, n)) continue;
            cnt.grid_nodes += (size_t)n[0] * n[1] * n[2];
            if (cnt.grid_nodes > GRID_MAX_NODES) {
                r = AK_ERR_BUDGET;
                goto fail;
            }
        }
        ak_skin_implicit* g = cnt.grid_nodes ? object_alloc(&cnt, alloc) : NULL;
        if (cnt.grid_nodes && !g) {
            r = AK_ERR_NO_MEMORY;
            goto fail;
        }
        if (g) {
            memcpy((unsigned char*)g + akp_align16(sizeof(ak_skin_implicit)),
                   (const unsigned char*)o + akp_align16(sizeof(ak_skin_implicit)), o->arrays_size);
            g->closed = o->closed, g->rest_volume = o->rest_volume;
            akp_free(alloc, o);
            o = g;
            size_t first = 0;
            for (size_t b = 0; b < jc; ++b) {
                float lo[3], h;
                uint32_t n[3];
                if (!grid_box(o, b, d.grid_resolution, lo, &h, n)) continue;
                uint32_t* I = o->grid_info + b * GRID_INFO;
                I[0] = n[0], I[1] = n[1], I[2] = n[2], I[3] = (uint32_t)first;
                float* G = o->bones + b * BONE_FLOATS + GRID_AT;
                G[0] = lo[0], G[1] = lo[1], G[2] = lo[2], G[3] = 1.0f / h;
                first += (size_t)n[0] * n[1] * n[2];
            }
            grid_task tasks[64];
            uint32_t th = d.thread_count > 1 ? d.thread_count : 1;
            for (uint32_t t = 0; t < th; ++t) tasks[t] = (grid_task){o, t, th};
            akp_run_tasks(grid_fill, tasks, sizeof tasks[0], th);
        }
    }
    {
        double rsum = 0.0;
        size_t rn = 0;
        for (size_t b = 0; b < jc; ++b)
            if (o->bones[b * BONE_FLOATS + 10] != 0.0f) rsum += o->bones[b * BONE_FLOATS + 8], ++rn;
        o->step_cap = rn ? (float)(0.5 * rsum / (double)rn) : 0.0f;
        o->bulge = d.bulge > 0.0f ? d.bulge : 0.0f;
        field_ctx fc = {o, NULL, o->bulge, NULL, NULL};
        for (size_t v = 0; v < nv; ++v) {
            ak_vec3 g;
            o->iso[v] = o->rep[v] == v ? field_eval(&fc, o->positions[v], &g) : o->iso[o->rep[v]];
        }
    }
    free(wscratch), free(normals), free(edges), free(part_start), free(part_verts);
    *out_implicit = o;
    return AK_OK;
fail:
    if (o) akp_free(alloc, o);
    free(wscratch), free(normals), free(edges), free(part_start), free(part_verts);
    return r;
}

void ak_skin_implicit_destroy(ak_skin_implicit* implicit) {
    if (!implicit) return;
    ak_allocator a = implicit->alloc;
    akp_free(a.alloc ? &a : NULL, implicit);
}

size_t ak_skin_implicit_vertex_count(const ak_skin_implicit* implicit) {
    return implicit ? implicit->vertex_count : 0;
}

uint16_t ak_skin_implicit_part(const ak_skin_implicit* implicit, size_t vertex_index) {
    return implicit && vertex_index < implicit->vertex_count ? implicit->part[vertex_index] : UINT16_MAX;
}

float ak_skin_implicit_iso(const ak_skin_implicit* implicit, size_t vertex_index) {
    return implicit && vertex_index < implicit->vertex_count ? implicit->iso[vertex_index] : 0.0f;
}

/* Inverse palette (12 floats per joint); false when a matrix is not finite or singular. */
static bool invert_palette(const ak_skin_implicit* o, const ak_mat4* palette, float* inv) {
    for (size_t j = 0; j < o->joint_count; ++j) {
        const float* m = palette[j].m;
        for (int i = 0; i < 16; ++i)
            if (!ak_finitef(m[i])) return false;
        double a[9] = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]}; /* columns */
        double c0 = a[4] * a[8] - a[5] * a[7], c1 = a[5] * a[6] - a[3] * a[8], c2 = a[3] * a[7] - a[4] * a[6];
        double det = a[0] * c0 + a[1] * c1 + a[2] * c2;
        if (!(fabs(det) > 1e-20)) {
            if (o->bones[j * BONE_FLOATS + 10] != 0.0f) return false;
            det = 1.0; /* unused joint: any value */
        }
        double id = 1.0 / det;
        /* inverse (column-major): rows of the inverse are cross products of columns */
        double r[9];
        r[0] = c0 * id, r[3] = c1 * id, r[6] = c2 * id;
        r[1] = (a[2] * a[7] - a[1] * a[8]) * id, r[4] = (a[0] * a[8] - a[2] * a[6]) * id,
        r[7] = (a[1] * a[6] - a[0] * a[7]) * id;
        r[2] = (a[1] * a[5] - a[2] * a[4]) * id, r[5] = (a[2] * a[3] - a[0] * a[5]) * id,
        r[8] = (a[0] * a[4] - a[1] * a[3]) * id;
        float* o12 = inv + 12 * j;
        for (int i = 0; i < 9; ++i) o12[i] = (float)r[i];
        double t[3] = {m[12], m[13], m[14]};
        for (int q = 0; q < 3; ++q) o12[9 + q] = (float)-(r[q] * t[0] + r[3 + q] * t[1] + r[6 + q] * t[2]);
    }
    return true;
}

float ak_skin_implicit_field(const ak_skin_implicit* implicit, ak_mat4_cspan palette, ak_vec3 x,
                             ak_vec3* out_gradient) {
    ak_vec3 g = ak_vec3_zero();
    float f = 0.0f;
    if (implicit) {
        float stack_inv[12 * 64];
        float* inv = NULL;
        bool ok = true;
        if (palette.ptr) {
            inv = implicit->joint_count <= 64 ? stack_inv : (float*)malloc(implicit->joint_count * 12 * sizeof(float));
            ok = inv && palette.count >= implicit->joint_count && invert_palette(implicit, palette.ptr, inv);
        }
        if (ok) {
            field_ctx fc = {implicit, inv, implicit->bulge, NULL, NULL};
            f = field_eval(&fc, x, &g);
        }
        if (inv && inv != stack_inv) free(inv);
    }
    if (out_gradient) *out_gradient = g;
    return f;
}

/* ---- cache file ------------------------------------------------------------------------------
 * "AKIS", u32 version 2, u64 key, u64 counts x5 (vertices, triangles, joints, adjacency,
 * sample capacity), u32 influence count, f32 step cap, f32 bulge, u32 zero, u64 grid nodes,
 * u64 joint pairs, u32 closed, f32 rest volume, then the arrays
 * exactly as the object holds them (little-endian hosts only: others refuse to read/write). */
#define FILE_HEADER 96

static bool host_little_endian(void) {
    const uint32_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void put_u64(unsigned char* p, uint64_t v) {
    akp_put_u32(p, (uint32_t)v);
    akp_put_u32(p + 4, (uint32_t)(v >> 32));
}
static uint64_t get_u64(const unsigned char* p) { return akp_get_u32(p) | ((uint64_t)akp_get_u32(p + 4) << 32); }

ak_result ak_skin_implicit_write_file(const ak_skin_implicit* implicit, uint64_t key, const char* path) {
    if (!implicit || !path) return AK_ERR_NULL_ARG;
    if (!host_little_endian()) return AK_ERR_UNSUPPORTED;
    unsigned char h[FILE_HEADER] = {0};
    memcpy(h, "AKIS", 4);
    akp_put_u32(h + 4, 2);
    put_u64(h + 8, key);
    put_u64(h + 16, implicit->vertex_count), put_u64(h + 24, implicit->triangle_count);
    put_u64(h + 32, implicit->joint_count), put_u64(h + 40, implicit->adj_count);
    put_u64(h + 48, implicit->sample_capacity);
    akp_put_u32(h + 56, implicit->influence_count);
    akp_put_f32(h + 60, implicit->step_cap), akp_put_f32(h + 64, implicit->bulge);
    put_u64(h + 72, implicit->grid_nodes);
    put_u64(h + 80, implicit->pair_count);
    akp_put_u32(h + 88, implicit->closed), akp_put_f32(h + 92, implicit->rest_volume);
    ak_atomic_file f;
    if (ak_atomic_file_open(&f, path) != AK_OK) return AK_ERR_IO;
    const unsigned char* arrays = (const unsigned char*)implicit + akp_align16(sizeof(ak_skin_implicit));
    bool ok = fwrite(h, 1, FILE_HEADER, f.f) == FILE_HEADER &&
              fwrite(arrays, 1, implicit->arrays_size, f.f) == implicit->arrays_size;
    if (!ok) {
        ak_atomic_file_abort(&f);
        return AK_ERR_IO;
    }
    return ak_atomic_file_commit(&f);
}

/* Whether the file holds at least the arrays the counts imply after the header (so that a
 * forged header cannot make the reader allocate more than the file's size). */
static bool file_holds(FILE* f, long header, const implicit_counts* c) {
    size_t need = akp_align16(sizeof(ak_skin_implicit));
    size_t nv = c->vertex_count, k = c->influence_count;
    bool ok = add_bytes(&need, nv, sizeof(ak_vec3)) && add_bytes(&need, 3 * c->triangle_count, 4) &&
              add_bytes(&need, nv * k, 2) && add_bytes(&need, nv * k, 4) && add_bytes(&need, nv, 2) &&
              add_bytes(&need, nv, 4) && add_bytes(&need, nv, 4) && add_bytes(&need, nv + 1, 4) &&
              add_bytes(&need, c->adj_count, 4) && add_bytes(&need, c->joint_count + 1, 4) &&
              add_bytes(&need, c->sample_capacity, SAMPLE_FLOATS * 4) &&
              add_bytes(&need, c->joint_count, BONE_FLOATS * 4) && add_bytes(&need, c->pair_count, PAIR_FLOATS * 4) &&
              add_bytes(&need, c->joint_count, GRID_INFO * 4) &&
              add_bytes(&need, c->grid_nodes, 16);
    if (!ok || fseek(f, 0, SEEK_END) != 0) return false;
    long end = ftell(f);
    if (end < 0 || fseek(f, header, SEEK_SET) != 0) return false;
    return (size_t)end - (size_t)header >= need - akp_align16(sizeof(ak_skin_implicit));
}

ak_result ak_skin_implicit_read_file(const char* path, uint64_t key, const ak_allocator* alloc,
                                     ak_skin_implicit** out_implicit) {
    if (out_implicit) *out_implicit = NULL;
    if (!path || !out_implicit) return AK_ERR_NULL_ARG;
    if (!host_little_endian()) return AK_ERR_UNSUPPORTED;
    FILE* f = fopen(path, "rb");
    if (!f) return AK_ERR_IO;
    unsigned char h[FILE_HEADER];
    ak_result r = AK_OK;
    ak_skin_implicit* o = NULL;
    if (fread(h, 1, FILE_HEADER, f) != FILE_HEADER || memcmp(h, "AKIS", 4) != 0 || akp_get_u32(h + 4) != 2) {
        r = AK_ERR_PARSE;
    } else if (get_u64(h + 8) != key) {
        r = AK_ERR_NOT_FOUND;
    } else {
        implicit_counts c = {get_u64(h + 16), get_u64(h + 24), get_u64(h + 32), get_u64(h + 40), get_u64(h + 48),
                             akp_get_u32(h + 56), get_u64(h + 72), get_u64(h + 80)};
        if (c.vertex_count == 0 || c.vertex_count > (1u << 24) || c.triangle_count > (1u << 26) ||
            c.joint_count == 0 || c.joint_count > 65535 || c.adj_count > 6 * c.triangle_count ||
            c.sample_capacity > 256 * c.joint_count || c.influence_count == 0 ||
            c.influence_count > AK_MAX_INFLUENCES || c.grid_nodes > GRID_MAX_NODES ||
            c.pair_count > c.adj_count) {
            r = AK_ERR_PARSE;
        } else if (!file_holds(f, FILE_HEADER, &c)) {
            r = AK_ERR_PARSE; /* shorter than its counts say: refused before allocating */
        } else if (!(o = object_alloc(&c, alloc))) {
            r = AK_ERR_NO_MEMORY;
        } else {
            unsigned char* arrays = (unsigned char*)o + akp_align16(sizeof(ak_skin_implicit));
            o->step_cap = akp_get_f32(h + 60), o->bulge = akp_get_f32(h + 64);
            o->closed = akp_get_u32(h + 88), o->rest_volume = akp_get_f32(h + 92);
            if (o->closed > 1 || !(o->rest_volume >= 0.0f && o->rest_volume < 1e30f)) r = AK_ERR_PARSE;
            if (fread(arrays, 1, o->arrays_size, f) != o->arrays_size) r = AK_ERR_PARSE;
            /* the arrays index each other: check every index before trusting them */
            for (size_t i = 0; r == AK_OK && i < 3 * c.triangle_count; ++i)
                if (o->indices[i] >= c.vertex_count) r = AK_ERR_PARSE;
            for (size_t v = 0; r == AK_OK && v < c.vertex_count; ++v)
                if (o->rep[v] > v || o->part[v] >= c.joint_count || o->adj_start[v] > o->adj_start[v + 1] ||
                    !ak_vec3_is_finite(o->positions[v]))
                    r = AK_ERR_PARSE;
            if (r == AK_OK && (o->adj_start[0] != 0 || o->adj_start[c.vertex_count] != c.adj_count)) r = AK_ERR_PARSE;
            for (size_t i = 0; r == AK_OK && i < c.adj_count; ++i)
                if (o->adj[i] >= c.vertex_count) r = AK_ERR_PARSE;
            for (size_t i = 0; r == AK_OK && i < c.vertex_count * c.influence_count; ++i)
                if (o->joints[i] >= c.joint_count) r = AK_ERR_PARSE;
            /* sample ranges: non-decreasing from 0, the last within the capacity */
            if (r == AK_OK && o->sample_start[0] != 0) r = AK_ERR_PARSE;
            for (size_t b = 0; r == AK_OK && b < c.joint_count; ++b)
                if (o->sample_start[b] > o->sample_start[b + 1]) r = AK_ERR_PARSE;
            if (r == AK_OK && o->sample_start[c.joint_count] > c.sample_capacity) r = AK_ERR_PARSE;
            if (r == AK_OK && !(o->step_cap >= 0.0f && o->step_cap < 1e30f && o->bulge >= 0.0f && o->bulge <= 10.0f))
                r = AK_ERR_PARSE;
            /* every float finite, every valid bone's scale and radius positive, weights valid */
            for (size_t i = 0; r == AK_OK && i < c.sample_capacity * SAMPLE_FLOATS; ++i)
                if (!ak_finitef(o->samples[i]) || fabsf(o->samples[i]) > 1e15f) r = AK_ERR_PARSE;
            for (size_t i = 0; r == AK_OK && i < c.joint_count * BONE_FLOATS; ++i)
                if (!ak_finitef(o->bones[i]) || fabsf(o->bones[i]) > 1e15f) r = AK_ERR_PARSE;
            for (size_t b = 0; r == AK_OK && b < c.joint_count; ++b)
                if (o->bones[b * BONE_FLOATS + 10] != 0.0f &&
                    !(o->bones[b * BONE_FLOATS + 3] > 1e-20f && o->bones[b * BONE_FLOATS + 8] > 1e-20f))
                    r = AK_ERR_PARSE;
            for (size_t v = 0; r == AK_OK && v < c.vertex_count; ++v)
                if (!ak_finitef(o->iso[v])) r = AK_ERR_PARSE;
            /* grids: each within the node pool, of a valid bone, with a positive step */
            for (size_t b = 0; r == AK_OK && b < c.joint_count; ++b) {
                const uint32_t* I = o->grid_info + b * GRID_INFO;
                if ((I[0] | I[1] | I[2] | I[3]) == 0) continue;
                if (c.grid_nodes == 0 || I[0] < 2 || I[1] < 2 || I[2] < 2 || I[0] > 129 || I[1] > 129 || I[2] > 129 ||
                    o->bones[b * BONE_FLOATS + 10] == 0.0f || !(o->bones[b * BONE_FLOATS + GRID_AT + 3] > 0.0f) ||
                    (uint64_t)I[3] + (uint64_t)I[0] * I[1] * I[2] > c.grid_nodes)
                    r = AK_ERR_PARSE;
            }
            /* joints: two distinct parts, every float finite */
            for (size_t p = 0; r == AK_OK && p < c.pair_count; ++p) {
                const float* P = o->pairs + p * PAIR_FLOATS;
                for (int q = 0; q < PAIR_FLOATS; ++q)
                    if (!ak_finitef(P[q]) || fabsf(P[q]) > 1e15f) r = AK_ERR_PARSE;
                if (r == AK_OK && !(P[0] >= 0.0f && P[0] < P[1] && P[1] < (float)c.joint_count && P[0] == floorf(P[0]) &&
                                    P[1] == floorf(P[1]) && P[11] >= 0.0f))
                    r = AK_ERR_PARSE;
            }
            for (size_t i = 0; r == AK_OK && i < 4 * c.grid_nodes; ++i)
                if (!ak_finitef(o->grid[i]) || fabsf(o->grid[i]) > 1e15f) r = AK_ERR_PARSE;
            if (r == AK_OK &&
                ak_skin_weights_validate((ak_u16_cspan){o->joints, c.vertex_count * c.influence_count},
                                         (ak_f32_cspan){o->weights, c.vertex_count * c.influence_count}, c.vertex_count,
                                         c.influence_count, c.joint_count, 0.0f, NULL) != AK_OK)
                r = AK_ERR_PARSE;
        }
    }
    fclose(f);
    if (r != AK_OK) {
        ak_skin_implicit_destroy(o);
        return r;
    }
    *out_implicit = o;
    return AK_OK;
}

ak_result ak_skin_implicit_cached(const ak_skin_implicit_desc* desc, const char* cache_path,
                                  const ak_allocator* alloc, ak_skin_implicit** out_implicit, bool* out_from_cache) {
    if (out_from_cache) *out_from_cache = false;
    if (out_implicit) *out_implicit = NULL;
    if (!desc || !out_implicit) return AK_ERR_NULL_ARG;
    uint64_t key = ak_skin_implicit_key(desc);
    if (cache_path && ak_skin_implicit_read_file(cache_path, key, alloc, out_implicit) == AK_OK) {
        if (out_from_cache) *out_from_cache = true;
        return AK_OK;
    }
    ak_result r = ak_skin_implicit_create(desc, alloc, out_implicit);
    if (r == AK_OK && cache_path) (void)ak_skin_implicit_write_file(*out_implicit, key, cache_path);
    return r;
}

/* ---- per frame ------------------------------------------------------------------------------- */

/* Broad-phase cells per axis: 16, fewer for skeletons so large that the masks would pass 2 MiB. */
static uint32_t bp_cells(const ak_skin_implicit* o) {
    size_t words = (o->joint_count + 63) / 64;
    uint32_t cells = 16;
    while (cells > 4 && (size_t)cells * cells * cells * words > ((size_t)1 << 18)) cells /= 2;
    return cells;
}

static size_t bp_mask_bytes(const ak_skin_implicit* o) {
    if (o->grid_nodes == 0) return 0;
    size_t c = bp_cells(o);
    return c * c * c * ((o->joint_count + 63) / 64) * sizeof(uint64_t);
}

/* The posed boxes of the grids (palette: bind to posed) into the broad phase's cells; with cull
 * (cull_build's bounds) and inv (the inverse palette), a cell whose every point lies past a
 * bone's capsule bound (its centre's bind-space distance from the capsule's segment exceeds the
 * bound plus the cell's half diagonal times the inverse's norm) leaves the bone out, as the
 * bound would at every point of the cell. */
static void bp_build(const ak_skin_implicit* o, const ak_mat4* palette, const float* inv, const float* cull, uint64_t* mask,
                     broad_phase* bp) {
    const uint32_t cells = bp_cells(o);
    const size_t words = (o->joint_count + 63) / 64;
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    float centre[3][16]; /* per axis, the cells' centres (bp_cells: at most 16 per axis) */
    bp->cells = cells, bp->words = words, bp->mask = mask, bp->empty = true;
    memset(mask, 0, (size_t)cells * cells * cells * words * sizeof(uint64_t));
    /* pass 0: the union of the posed boxes; pass 1: the bits */
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t b = 0; b < o->joint_count; ++b) {
            const uint32_t* I = o->grid_info + b * GRID_INFO;
            if (I[0] < 2) continue;
            const float* G = o->bones + b * BONE_FLOATS + GRID_AT;
            const float* m = palette[b].m;
            const float h = 1.0f / G[3];
            float c[3], e[3], wc[3], we[3];
            for (int q = 0; q < 3; ++q) e[q] = 0.5f * h * (float)(I[q] - 1), c[q] = G[q] + e[q];
            for (int q = 0; q < 3; ++q) {
                wc[q] = m[q] * c[0] + m[4 + q] * c[1] + m[8 + q] * c[2] + m[12 + q];
                we[q] = fabsf(m[q]) * e[0] + fabsf(m[4 + q]) * e[1] + fabsf(m[8 + q]) * e[2];
                we[q] = we[q] * 1.0001f + 1e-6f * fabsf(wc[q]); /* rounding of the inverse transform */
            }
            if (pass == 0) {
                for (int q = 0; q < 3; ++q) lo[q] = fminf(lo[q], wc[q] - we[q]), hi[q] = fmaxf(hi[q], wc[q] + we[q]);
                continue;
            }
            uint32_t a[3], z[3];
            for (int q = 0; q < 3; ++q) {
                float pa = (wc[q] - we[q] - bp->lo[q]) * bp->inv_cell[q], pz = (wc[q] + we[q] - bp->lo[q]) * bp->inv_cell[q];
                a[q] = pa > 0.0f ? (pa < (float)cells ? (uint32_t)pa : cells - 1) : 0;
                z[q] = pz > 0.0f ? (pz < (float)cells ? (uint32_t)pz : cells - 1) : 0;
            }
            const uint64_t bit = (uint64_t)1 << (b & 63);
            const float* C = cull ? cull + b * CULL_FLOATS : NULL;
            const float* M = inv + 12 * b;
            float reach2 = 0.0f;
            if (C && C[7] > 0.0f) {
                float fro = 0.0f, diag = 0.0f;
                for (int q = 0; q < 9; ++q) fro += M[q] * M[q];
                for (int q = 0; q < 3; ++q) diag += 1.0f / (bp->inv_cell[q] * bp->inv_cell[q]);
                const float reach = sqrtf(C[7]) + sqrtf(fro) * 0.5f * sqrtf(diag) * 1.001f;
                reach2 = reach * reach;
                if (!ak_finitef(reach2)) reach2 = 0.0f;
            }
            for (uint32_t k = a[2]; k <= z[2]; ++k) {
                const float zz = centre[2][k];
                for (uint32_t j = a[1]; j <= z[1]; ++j) {
                    const float y = centre[1][j];
                    for (uint32_t i = a[0]; i <= z[0]; ++i) {
                        if (reach2 > 0.0f) {
                            const float x = centre[0][i];
                            const float ax = M[0] * x + M[3] * y + M[6] * zz + M[9] - C[0];
                            const float ay = M[1] * x + M[4] * y + M[7] * zz + M[10] - C[1];
                            const float az = M[2] * x + M[5] * y + M[8] * zz + M[11] - C[2];
                            float t = (ax * C[3] + ay * C[4] + az * C[5]) * C[6];
                            t = t > 0.0f ? (t < 1.0f ? t : 1.0f) : 0.0f;
                            const float wx = ax - C[3] * t, wy = ay - C[4] * t, wz = az - C[5] * t;
                            if (wx * wx + wy * wy + wz * wz > reach2) continue;
                        }
                        mask[((size_t)i + cells * ((size_t)j + (size_t)cells * k)) * words + b / 64] |= bit;
                    }
                }
            }
        }
        if (pass == 0) {
            if (!(lo[0] <= hi[0]) || !ak_finitef(lo[0] + lo[1] + lo[2] + hi[0] + hi[1] + hi[2])) return;
            bp->empty = false;
            for (int q = 0; q < 3; ++q) {
                float ext = fmaxf(hi[q] - lo[q], 1e-20f);
                bp->lo[q] = lo[q], bp->inv_cell[q] = (float)cells / ext;
                for (uint32_t i = 0; i < cells; ++i) centre[q][i] = bp->lo[q] + ((float)i + 0.5f) / bp->inv_cell[q];
            }
        }
    }
}

/* The capsule bounds of the grids' fields (CULL_FLOATS per bone, bind space). A node stores
 * max(HRBF, capsule distance) inside the bone's bounding sphere and the support radius outside
 * it, so at least min(capsule distance, support radius); the capsule distance is 1-Lipschitz, so
 * at a point farther than the support radius plus a cell diagonal from the capsule every corner
 * of its cell holds at least the support radius, and so does their interpolation: field 0. */
static void cull_build(const ak_skin_implicit* o, float* cull) {
    for (size_t b = 0; b < o->joint_count; ++b) {
        float* C = cull + b * CULL_FLOATS;
        memset(C, 0, CULL_FLOATS * sizeof(float));
        const float* B = o->bones + b * BONE_FLOATS;
        const uint32_t* I = o->grid_info + b * GRID_INFO;
        if (B[10] == 0.0f || I[0] < 2 || !(B[GRID_AT + 3] > 0.0f)) continue;
        const float* K = B + CAPSULE_AT;
        const float r = B[8], h = 1.0f / B[GRID_AT + 3];
        float scale = fmaxf(K[6], r);
        for (int q = 0; q < 6; ++q) scale = fmaxf(scale, fabsf(K[q]));
        const float margin = 1e-3f * r + 1e-5f * scale;
        const ak_vec3 a = ak_vec3_make(K[0], K[1], K[2]), e = ak_vec3_make(K[3], K[4], K[5]);
        if (!(r > 0.0f)) continue;
        const ak_vec3 ab = ak_vec3_sub(e, a);
        const float l2 = ak_vec3_dot(ab, ab), reach = K[6] + r + 1.7321f * h + margin;
        C[0] = a.x, C[1] = a.y, C[2] = a.z, C[3] = ab.x, C[4] = ab.y, C[5] = ab.z;
        C[6] = l2 > 0.0f ? 1.0f / l2 : 0.0f;
        C[7] = reach * reach;
        if (!ak_finitef(C[6]) || !ak_finitef(C[7])) memset(C, 0, CULL_FLOATS * sizeof(float));
    }
}

/* Per bone and frame (BF_FLOATS): the map from a posed point to the bone's grid coordinates
 * (the inverse palette matrix inv, then (y - grid origin) / h, folded into one affine map), the
 * capsule bound of cull_build in grid units, the grid's upper corner and the support radius. A
 * point's grid coordinates round differently from the two-step map's (a few ulps); the bound's
 * margin (cull_build) covers that, and the point's cell and fractions come from the same
 * coordinates as its bound. */
static void bone_frames_build(const ak_skin_implicit* o, const float* inv, const float* cull, float* bf) {
    for (size_t b = 0; b < o->joint_count; ++b) {
        float* F = bf + b * BF_FLOATS;
        memset(F, 0, BF_FLOATS * sizeof(float));
        const uint32_t* I = o->grid_info + b * GRID_INFO;
        if (I[0] < 2) continue;
        const float* G = o->bones + b * BONE_FLOATS + GRID_AT;
        const float* M = inv + 12 * b;
        const float s = G[3];
        for (int q = 0; q < 9; ++q) F[q] = M[q] * s;
        for (int q = 0; q < 3; ++q) F[9 + q] = (M[9 + q] - G[q]) * s;
        const float* C = cull + b * CULL_FLOATS;
        if (C[7] > 0.0f) {
            for (int q = 0; q < 3; ++q) F[12 + q] = (C[q] - G[q]) * s, F[15 + q] = C[3 + q] * s;
            F[18] = C[6] / (s * s);
            F[19] = C[7] * (s * s);
            if (!ak_finitef(F[18]) || !ak_finitef(F[19])) F[19] = 0.0f;
        }
        for (int q = 0; q < 3; ++q) F[20 + q] = (float)(I[q] - 1);
        F[23] = 1.0f / o->bones[b * BONE_FLOATS + 8];
        F[24] = o->bones[b * BONE_FLOATS + 8];
    }
}

/* The SIMD broad phase (SSE2, at most 64 bones): the bones of every distinct cell mask, in bone
 * order, as groups of 4 bone records (bone_frames_build's, lane-interleaved; a padding lane has an
 * empty box); cell_group[2 cell] its first group and count (UINT32_MAX: more groups than
 * GROUP_CAP, the scalar loop). table: [2 cells^3] scratch for the masks' hash. */
static void groups_build(const float* bf, broad_phase* bp, uint32_t* cell_group, uint32_t* table,
                         float* group, uint32_t* group_bone) {
    bp->cell_group = NULL, bp->group = group, bp->group_bone = group_bone;
#if AK_SIMD_SSE2
    if (bp->empty || bp->words != 1) return;
    const size_t ncell = (size_t)bp->cells * bp->cells * bp->cells, tsize = 2 * ncell; /* a power of 2 */
    memset(table, 0xff, tsize * sizeof(uint32_t));
    uint32_t used = 0;
    for (size_t cell = 0; cell < ncell; ++cell) {
        const uint64_t m = bp->mask[cell];
        uint32_t* cg = cell_group + 2 * cell;
        cg[0] = 0, cg[1] = 0;
        if (!m) continue;
        size_t h = (size_t)((m * 0x9E3779B97F4A7C15ull) >> 32) & (tsize - 1);
        while (table[h] != UINT32_MAX && bp->mask[table[h]] != m) h = (h + 1) & (tsize - 1);
        if (table[h] != UINT32_MAX) { /* a cell with the same bones: its groups */
            cg[0] = cell_group[2 * (size_t)table[h]], cg[1] = cell_group[2 * (size_t)table[h] + 1];
            continue;
        }
        table[h] = (uint32_t)cell;
        const uint32_t count = (popcount64(m) + 3) / 4;
        if (used + count > GROUP_CAP) {
            cg[1] = UINT32_MAX;
            continue;
        }
        cg[0] = used, cg[1] = count;
        uint64_t bits = m;
        for (uint32_t g = used; g < used + count; ++g) {
            float* G = group + (size_t)g * GROUP_FLOATS;
            for (unsigned l = 0; l < 4; ++l) {
                uint32_t b = UINT32_MAX;
                if (bits) b = ctz64(bits), bits &= bits - 1;
                group_bone[4 * (size_t)g + l] = b;
                for (int q = 0; q < 24; ++q) G[4 * q + l] = b != UINT32_MAX ? bf[(size_t)b * BF_FLOATS + q] : 0.0f;
                if (b == UINT32_MAX) G[4 * 20 + l] = G[4 * 21 + l] = G[4 * 22 + l] = -1.0f; /* never in the box */
            }
        }
        used += count;
    }
    bp->cell_group = cell_group;
#else
    (void)bf, (void)cell_group, (void)table;
#endif
}

/* Scratch of groups_build: cell_group and table, the groups and their bones (0 without grids). */
static size_t groups_bytes(const ak_skin_implicit* o) {
    if (o->grid_nodes == 0) return 0;
    const size_t c = bp_cells(o), ncell = c * c * c;
    return align64(2 * ncell * sizeof(uint32_t)) + align64(2 * ncell * sizeof(uint32_t)) +
           align64((size_t)GROUP_CAP * GROUP_FLOATS * sizeof(float)) + align64((size_t)GROUP_CAP * 4 * sizeof(uint32_t));
}

size_t ak_skin_implicit_scratch_size(const ak_skin_implicit* implicit, size_t palette_count) {
    if (!implicit) return 0;
    ak_mat4 probe;
    ak_skin_job dq = {.method = AK_SKIN_DQS, .palette = {&probe, palette_count}};
    size_t nv = implicit->vertex_count;
    return 64 + align64(implicit->joint_count * 12 * sizeof(float)) + align64(ak_skin_job_scratch_size(&dq)) +
           align64(nv) + 3 * align64(nv * sizeof(ak_vec3)) + align64(bp_mask_bytes(implicit)) +
           align64(implicit->pair_count * PAIR_FRAME * sizeof(float)) + align64(implicit->joint_count * CULL_FLOATS * sizeof(float)) +
           align64(implicit->joint_count * BF_FLOATS * sizeof(float)) + groups_bytes(implicit) +
           align64(nv * sizeof(uint32_t)) + align64(nv) + align64(implicit->triangle_count * sizeof(uint32_t)) +
           align64(nv * sizeof(uint32_t)) + align64((implicit->joint_count + 1) * sizeof(uint32_t)) + align64(nv * 8 * sizeof(float)) +
           align64((implicit->joint_count + 1) * sizeof(uint32_t)) + align64(2 * implicit->pair_count * sizeof(uint32_t));
}

enum { ST_KEEP = 0, ST_MOVED = 1, ST_STOPPED = 2, ST_CONTACT = 8 };

typedef struct run_ctx {
    const ak_skin_implicit* o;
    field_ctx fc;
    uint32_t iterations;
    ak_vec3* pos;
    ak_vec3* prev;
    ak_vec3* grad;
    uint8_t* state;
    const ak_vec3* dq;   /* the DQS result */
    const float* frame;  /* [pair_count * PAIR_FRAME] */
    const uint32_t* fold_start; /* [joint_count + 1]: per part, its folded joints (fold_lists_build) */
    const uint32_t* fold_pair;  /* [2 * pair_count] */
    /* the lane kernel of the projections (NULL: project, one vertex at a time), its lanes and
     * its per-frame data; set only with grids and at most 64 bones (one mask word per cell) */
    unsigned (*lanes_fn)(const akp_implicit_field* fd, akp_implicit_lanes* l, unsigned live);
    unsigned lanes;
    akp_implicit_field lanes_fd;
    float unchecked_below; /* project's: FLT_MAX in the rounds before the last, UNCHECKED_EPS in
                              the first projection when rounds follow, else 0 */
} run_ctx;

/* One vertex's Newton march (project and the lane driver project_lanes share it): the point,
 * where it started, the previous gradient, the steps taken and the state. */
typedef struct march {
    ak_vec3 x, start, gprev;
    uint32_t it;
    uint8_t st;
} march;

static void march_start(march* m, ak_vec3 p, bool first) {
    m->x = m->start = p;
    m->gprev = ak_vec3_zero();
    m->it = 0;
    m->st = first ? ST_KEEP : ST_MOVED;
}

/* One step of the march from the field F and its gradient g at m->x; true when the march ends
 * (m->x is then its end, g the gradient to keep). A step taken where |F - iso| <
 * unchecked_below is the last one. */
static bool march_step(const run_ctx* c, float iso, march* m, float F, ak_vec3 g, float unchecked_below) {
    const float e = iso - F;
    if (fabsf(e) < ISO_EPS || m->it == c->iterations) return true;
    const float gl2 = ak_vec3_length_sq(g);
    if (!(gl2 > 1e-20f)) return true;
    if (m->it > 0 && ak_vec3_dot(g, m->gprev) < STOP_COS * sqrtf(gl2 * ak_vec3_length_sq(m->gprev))) {
        m->st = ST_STOPPED; /* gradient discontinuity: a contact surface */
        return true;
    }
    ak_vec3 step = ak_vec3_scale(g, e / gl2);
    const float sl = ak_vec3_length(step);
    if (sl > c->o->step_cap) step = ak_vec3_scale(step, c->o->step_cap / sl);
    m->x = ak_vec3_add(m->x, step);
    m->gprev = g;
    if (m->st == ST_KEEP) m->st = ST_MOVED;
    if (fabsf(e) < unchecked_below) return true;
    ++m->it;
    return false;
}

/* The march's end into *p and *out_g (never NaN out: a non-finite end keeps the start); returns
 * the state. */
static uint8_t march_end(march* m, ak_vec3 g, ak_vec3* p, ak_vec3* out_g) {
    if (!ak_vec3_is_finite(m->x) || !ak_vec3_is_finite(g)) {
        m->x = m->start;
        g = ak_vec3_zero();
        m->st = ST_STOPPED;
    }
    *p = m->x;
    *out_g = g;
    return m->st;
}

/* Newton steps from *p towards the vertex's iso-value; returns the state. A step taken where
 * |F - iso| < unchecked_below is the last one and its end is not evaluated (out_g is then the
 * gradient where it started): used where a later relaxation round evaluates the point anyway
 * (0: every step is checked). */
static uint8_t project(const run_ctx* c, float iso, ak_vec3* p, ak_vec3* out_g, bool first, float unchecked_below) {
    march m;
    march_start(&m, *p, first);
    ak_vec3 g;
    for (;;) {
        const float F = field_eval(&c->fc, m.x, &g);
        if (march_step(c, iso, &m, F, g, unchecked_below)) break;
    }
    return march_end(&m, g, p, out_g);
}

/* The contact planes of the joints (the paper's contact surface f_i = f_j, which for two parts
 * of equal thickness meeting at a hinge is the plane bisecting their axes; taken from the bone
 * axes so that it stays defined when a deep fold saturates both fields): per joint and frame,
 * the posed centre (the mean of the centre moved by either part), the normal unit(R_i u_i -
 * R_j u_j) and the inner side (the sum of the posed axes, towards which the joint folds). */
static void contact_frames(const ak_skin_implicit* o, const ak_mat4* palette, float* frame) {
    for (size_t p = 0; p < o->pair_count; ++p) {
        const float* P = o->pairs + p * PAIR_FLOATS;
        float* F = frame + p * PAIR_FRAME;
        memset(F, 0, PAIR_FRAME * sizeof(float));
        if (!(P[11] > 0.0f)) continue;
        const float* mi = palette[(size_t)P[0]].m;
        const float* mj = palette[(size_t)P[1]].m;
        ak_vec3 c = ak_vec3_make(P[2], P[3], P[4]), ui = ak_vec3_make(P[5], P[6], P[7]), uj = ak_vec3_make(P[8], P[9], P[10]);
        ak_vec3 ci = ak_vec3_make(mi[0] * c.x + mi[4] * c.y + mi[8] * c.z + mi[12], mi[1] * c.x + mi[5] * c.y + mi[9] * c.z + mi[13],
                                  mi[2] * c.x + mi[6] * c.y + mi[10] * c.z + mi[14]);
        ak_vec3 cj = ak_vec3_make(mj[0] * c.x + mj[4] * c.y + mj[8] * c.z + mj[12], mj[1] * c.x + mj[5] * c.y + mj[9] * c.z + mj[13],
                                  mj[2] * c.x + mj[6] * c.y + mj[10] * c.z + mj[14]);
        ak_vec3 pi = ak_vec3_normalize(ak_vec3_make(mi[0] * ui.x + mi[4] * ui.y + mi[8] * ui.z, mi[1] * ui.x + mi[5] * ui.y + mi[9] * ui.z,
                                                    mi[2] * ui.x + mi[6] * ui.y + mi[10] * ui.z));
        ak_vec3 pj = ak_vec3_normalize(ak_vec3_make(mj[0] * uj.x + mj[4] * uj.y + mj[8] * uj.z, mj[1] * uj.x + mj[5] * uj.y + mj[9] * uj.z,
                                                    mj[2] * uj.x + mj[6] * uj.y + mj[10] * uj.z));
        ak_vec3 n = ak_vec3_sub(pi, pj);
        float ln = ak_vec3_length(n);
        if (!(ln > 1e-3f) || !ak_finitef(ln)) continue;
        n = ak_vec3_scale(n, 1.0f / ln);
        ak_vec3 cp = ak_vec3_scale(ak_vec3_add(ci, cj), 0.5f);
        if (!ak_vec3_is_finite(cp)) continue;
        /* folded this far (the rest axes are opposite: a straight limb has no inner side) */
        ak_vec3 in = ak_vec3_add(pi, pj), rest_in = ak_vec3_add(ui, uj);
        float fold = ak_vec3_length(in) - ak_vec3_length(rest_in);
        F[0] = cp.x, F[1] = cp.y, F[2] = cp.z, F[3] = n.x, F[4] = n.y, F[5] = n.z;
        F[6] = fold > CONTACT_FOLD ? 1.0f : 0.0f;
        ak_vec3 ind = ak_vec3_normalize(in);
        if (ak_vec3_is_finite(ind)) F[8] = ind.x, F[9] = ind.y, F[10] = ind.z;
        F[12] = pi.x, F[13] = pi.y, F[14] = pi.z, F[16] = pj.x, F[17] = pj.y, F[18] = pj.z;
    }
}

/* Per part, its folded joints (contact_frames' flag) in joint order: fold_pair[fold_start[part]
 * .. fold_start[part + 1]) (CSR over joint_count parts); parts out of range have none
 * (FOLD_FIRST, FOLD_END). */
static void fold_lists_build(const ak_skin_implicit* o, const float* frame, uint32_t* fold_start, uint32_t* fold_pair) {
    const size_t nj = o->joint_count;
    memset(fold_start, 0, (nj + 1) * sizeof(uint32_t));
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t p = 0; p < o->pair_count; ++p) {
            if (frame[p * PAIR_FRAME + 6] == 0.0f) continue;
            const float* P = o->pairs + p * PAIR_FLOATS;
            const uint32_t i = (uint32_t)P[0], j = (uint32_t)P[1];
            for (int e = 0; e < (i == j ? 1 : 2); ++e) {
                const uint32_t part = e ? j : i;
                if (part >= nj) continue;
                if (pass == 0) ++fold_start[part + 1];
                else fold_pair[fold_start[part]++] = (uint32_t)p;
            }
        }
        if (pass == 0)
            for (size_t b = 0; b < nj; ++b) fold_start[b + 1] += fold_start[b];
        else /* the fill moved every start to the next part's: back by one part */
            for (size_t b = nj; b > 0; --b) fold_start[b] = fold_start[b - 1];
    }
    fold_start[0] = 0;
}
#define FOLD_FIRST(c, part) ((part) < (c)->o->joint_count ? (c)->fold_start[(part)] : 0u)
#define FOLD_END(c, part) ((part) < (c)->o->joint_count ? (c)->fold_start[(part) + 1] : 0u)

/* One vertex against the contact planes of its part's joints (those folded by more than a
 * little): within a joint's reach, a vertex that the projection or DQS leaves within a band
 * of the plane goes back to its DQS position (the projection folds the skin there), and a
 * vertex past the plane (beyond its rest offset, capped at a small gap) is moved onto it. */
static void contact_vertex(const run_ctx* c, size_t v, bool revert) {
    const ak_skin_implicit* o = c->o;
    const uint32_t part = o->part[v];
    const ak_vec3 vb = o->positions[v];
    ak_vec3 x = c->pos[v];
    bool touched = false;
    for (uint32_t k = FOLD_FIRST(c, part); k < FOLD_END(c, part); ++k) {
        const size_t p = c->fold_pair[k];
        const float* P = o->pairs + p * PAIR_FLOATS;
        const float* F = c->frame + p * PAIR_FRAME;
        float side;
        if ((uint32_t)P[0] == part) side = 1.0f;
        else if ((uint32_t)P[1] == part) side = -1.0f;
        else continue;
        ak_vec3 cb = ak_vec3_make(P[2], P[3], P[4]);
        if (!(ak_vec3_length_sq(ak_vec3_sub(vb, cb)) < P[11] * P[11])) continue; /* the reach (near_fold) */
        const ak_vec3 cp = ak_vec3_make(F[0], F[1], F[2]), n = ak_vec3_make(F[3], F[4], F[5]);
        const ak_vec3 nr = ak_vec3_make(P[13], P[14], P[15]);
        const float gap = 0.02f * P[12], band = 0.4f * P[12];
        /* the inner side of the fold only: the half-space the folded axes point into */
        if (ak_vec3_dot(ak_vec3_sub(x, cp), ak_vec3_make(F[8], F[9], F[10])) <= 0.0f &&
            ak_vec3_dot(ak_vec3_sub(c->dq[v], cp), ak_vec3_make(F[8], F[9], F[10])) <= 0.0f)
            continue;
        float s_rest = side * ak_vec3_dot(ak_vec3_sub(vb, cb), nr);
        float need = s_rest < gap ? s_rest : gap;
        float s = side * ak_vec3_dot(ak_vec3_sub(x, cp), n);
        float s_dq = side * ak_vec3_dot(ak_vec3_sub(c->dq[v], cp), n);
        if (revert && (s < need + band || s_dq < need + band)) {
            x = c->dq[v];
            s = s_dq;
            touched = true;
        }
        if (s < need) {
            x = ak_vec3_add(x, ak_vec3_scale(n, side * (need - s)));
            touched = true;
        }
    }
    if (touched && ak_vec3_is_finite(x)) {
        c->pos[v] = x;
        c->state[v] = ST_STOPPED | ST_CONTACT;
    }
}

static bool projectable(float iso) { return iso > 0.02f && iso < 0.98f; }

/* Volume kept at contacts (closed meshes): the contact planes remove the parts' overlap, so
 * the skin around each folded joint swells along the volume gradient, with weight (1 -
 * distance / reach)^2 over BULGE_REACH seam radii of the joint at the bind pose (contact
 * vertices excepted), by the amount that brings the enclosed volume back to the rest volume
 * (Newton steps on the linearised volume; each vertex's move capped at a seam radius). Serial,
 * so the result does not depend on the thread count. grad is scratch for nv vectors. */
static void keep_volume(const run_ctx* c, ak_vec3* grad, uint32_t* list, uint8_t* flag, uint32_t* tris, float* cache) {
    const ak_skin_implicit* o = c->o;
    ak_vec3* pos = c->pos;
    const size_t nv = o->vertex_count;
    /* the vertices that may move (welded representatives near a folded joint of their part,
     * in index order) and the triangles that touch them; the others keep their volume */
    size_t nl = 0, nt = 0;
    for (size_t v = 0; v < nv; ++v) {
        flag[v] = 0;
        if (o->rep[v] != v || (c->state[v] & ST_CONTACT) || !projectable(o->iso[v])) continue;
        for (uint32_t k = FOLD_FIRST(c, o->part[v]); k < FOLD_END(c, o->part[v]); ++k) {
            const float* P = o->pairs + (size_t)c->fold_pair[k] * PAIR_FLOATS;
            float dist = ak_vec3_length(ak_vec3_sub(o->positions[v], ak_vec3_make(P[2], P[3], P[4])));
            if (1.0f - dist / (BULGE_REACH * P[12]) > 0.0f) {
                flag[v] = 1, list[nl++] = (uint32_t)v;
                break;
            }
        }
    }
    if (nl == 0) return;
    double fixed = 0.0;
    for (size_t t = 0; t < o->triangle_count; ++t) {
        const uint32_t* ix = o->indices + 3 * t;
        uint32_t ra = o->rep[ix[0]], rb = o->rep[ix[1]], rd = o->rep[ix[2]];
        if (flag[ra] | flag[rb] | flag[rd]) {
            tris[nt++] = (uint32_t)t;
            continue;
        }
        fixed += (double)ak_vec3_dot(pos[ra], ak_vec3_cross(pos[rb], pos[rd])) / 6.0;
    }
    for (int it = 0; it < 3; ++it) {
        double vol = fixed;
        for (size_t i = 0; i < nt; ++i) {
            const uint32_t* ix = o->indices + 3 * tris[i];
            grad[o->rep[ix[0]]] = grad[o->rep[ix[1]]] = grad[o->rep[ix[2]]] = ak_vec3_zero();
        }
        for (size_t i = 0; i < nt; ++i) {
            const uint32_t* ix = o->indices + 3 * tris[i];
            uint32_t ra = o->rep[ix[0]], rb = o->rep[ix[1]], rd = o->rep[ix[2]];
            ak_vec3 a = pos[ra], b = pos[rb], d = pos[rd];
            vol += (double)ak_vec3_dot(a, ak_vec3_cross(b, d)) / 6.0;
            grad[ra] = ak_vec3_add(grad[ra], ak_vec3_scale(ak_vec3_cross(b, d), 1.0f / 6.0f));
            grad[rb] = ak_vec3_add(grad[rb], ak_vec3_scale(ak_vec3_cross(d, a), 1.0f / 6.0f));
            grad[rd] = ak_vec3_add(grad[rd], ak_vec3_scale(ak_vec3_cross(a, b), 1.0f / 6.0f));
        }
        const double dv = (double)o->rest_volume - vol;
        if (!isfinite(dv) || fabs(dv) < 1e-4 * (double)o->rest_volume) break;
        /* the weight, cap and direction of each vertex (from its own position, which only its
         * own step changes), then the steps that sum to the missing volume */
        double sum = 0.0;
        for (size_t i = 0; i < nl; ++i) {
            const size_t v = list[i];
            float w = 0.0f, cap = 0.0f;
            ak_vec3 dir = ak_vec3_zero();
            for (uint32_t k = FOLD_FIRST(c, o->part[v]); k < FOLD_END(c, o->part[v]); ++k) {
                const size_t p = c->fold_pair[k];
                const float* P = o->pairs + p * PAIR_FLOATS;
                const float* F = c->frame + p * PAIR_FRAME;
                /* the inner side of the fold only (where the parts press together),
                 * fading in over a seam radius */
                float inner = ak_vec3_dot(ak_vec3_sub(pos[v], ak_vec3_make(F[0], F[1], F[2])), ak_vec3_make(F[8], F[9], F[10])) / P[12];
                if (!(inner > 0.0f)) continue;
                inner = inner < 1.0f ? inner * inner * (3.0f - 2.0f * inner) : 1.0f;
                float dist = ak_vec3_length(ak_vec3_sub(o->positions[v], ak_vec3_make(P[2], P[3], P[4])));
                float u = 1.0f - dist / (BULGE_REACH * P[12]);
                if (u > 0.0f && inner * u * u > w) {
                    /* away from the part's posed axis (a smooth direction, unlike the
                     * per-vertex volume gradient of a crumpled surface) */
                    ak_vec3 a = (uint32_t)P[0] == o->part[v] ? ak_vec3_make(F[12], F[13], F[14])
                                                             : ak_vec3_make(F[16], F[17], F[18]);
                    ak_vec3 rel = ak_vec3_sub(pos[v], ak_vec3_make(F[0], F[1], F[2]));
                    ak_vec3 rad = ak_vec3_normalize(ak_vec3_sub(rel, ak_vec3_scale(a, ak_vec3_dot(rel, a))));
                    if (!ak_vec3_is_finite(rad)) continue;
                    w = inner * u * u, cap = P[12], dir = rad;
                }
            }
            float* W = cache + 8 * i;
            W[0] = 0.0f;
            if (w == 0.0f) continue;
            const float e = ak_vec3_dot(grad[v], dir); /* volume change per unit move */
            if (!(e > 0.0f) || !ak_finitef(e)) continue;
            sum += (double)w * e;
            W[0] = w, W[1] = cap, W[2] = dir.x, W[3] = dir.y, W[4] = dir.z;
        }
        const float k = (float)(dv / sum);
        if (!(sum > 0.0 && isfinite(k))) break;
        for (size_t i = 0; i < nl; ++i) {
            const float* W = cache + 8 * i;
            if (W[0] == 0.0f) continue;
            const size_t v = list[i];
            float step = k * W[0];
            step = ak_clampf(step, -W[1], W[1]);
            ak_vec3 q = ak_vec3_add(pos[v], ak_vec3_scale(ak_vec3_make(W[2], W[3], W[4]), step));
            if (ak_vec3_is_finite(q)) pos[v] = q, c->state[v] |= ST_MOVED;
        }
    }
}


/* Whether vertex v follows one joint rigidly (a single influence of weight 1) and its DQS
 * position lies in a broad-phase cell that no other bone's field reaches: its field is then
 * that of its rest position, i.e. its iso-value, and the projection would keep it. */
static bool rigid_alone(const run_ctx* c, size_t v) {
    const ak_skin_implicit* o = c->o;
    const broad_phase* bp = c->fc.bp;
    if (!bp || bp->empty) return false;
    const uint32_t k = o->influence_count;
    const float* w = o->weights + v * k;
    const uint16_t* j = o->joints + v * k;
    size_t b = SIZE_MAX;
    for (uint32_t q = 0; q < k; ++q) {
        if (w[q] == 0.0f) continue;
        if (w[q] != 1.0f || b != SIZE_MAX) return false;
        b = j[q];
    }
    if (b == SIZE_MAX) return false;
    ak_vec3 x = c->pos[v];
    float p[3] = {(x.x - bp->lo[0]) * bp->inv_cell[0], (x.y - bp->lo[1]) * bp->inv_cell[1], (x.z - bp->lo[2]) * bp->inv_cell[2]};
    const float top = (float)bp->cells;
    if (!(p[0] >= 0.0f && p[1] >= 0.0f && p[2] >= 0.0f && p[0] < top && p[1] < top && p[2] < top)) return false;
    const size_t cell = (size_t)p[0] + bp->cells * ((size_t)p[1] + bp->cells * (size_t)p[2]);
    const uint64_t* mw = bp->mask + cell * bp->words;
    for (size_t q = 0; q < bp->words; ++q)
        if (mw[q] != (q == b / 64 ? (uint64_t)1 << (b & 63) : 0u)) return false;
    return true;
}

/* Whether contact_vertex can act on vertex v: a joint of its part is folded and v lies within
 * the joint's reach at the bind pose. */
static bool near_fold(const run_ctx* c, size_t v) {
    const ak_skin_implicit* o = c->o;
    const uint32_t part = o->part[v];
    for (uint32_t k = FOLD_FIRST(c, part); k < FOLD_END(c, part); ++k) {
        const float* P = o->pairs + (size_t)c->fold_pair[k] * PAIR_FLOATS;
        if (ak_vec3_length_sq(ak_vec3_sub(o->positions[v], ak_vec3_make(P[2], P[3], P[4]))) < P[11] * P[11]) return true;
    }
    return false;
}

/* Phases 0 (first projection) and 2 (re-projection) of run_worker over list[begin, end) with the
 * lane kernel: c->lanes vertices march at once, each lane taking the next vertex of the list as
 * soon as its own march ends. The kernel takes the steps march_step takes, with the bits of
 * field_eval, and march_end finishes each march, so the results are the scalar path's bits. */
static void project_lanes(const run_ctx* c, const uint32_t* list, size_t begin, size_t end, int phase) {
    const ak_skin_implicit* o = c->o;
    akp_implicit_lanes L;
    ak_vec3 start[16];
    uint32_t vert[16];
    const unsigned W = c->lanes;
    akp_implicit_field fd = c->lanes_fd;
    fd.unchecked_below = c->unchecked_below;
    unsigned live = 0;
    size_t i = begin;
    memset(&L, 0, sizeof L);
    for (;;) {
        for (unsigned l = 0; l < W; ++l) {
            if (live >> l & 1u) continue;
            while (i < end) {
                const size_t v = list ? list[i] : i;
                ++i;
                if (o->rep[v] != v || !projectable(o->iso[v])) continue;
                if (phase == 0 ? rigid_alone(c, v) : c->state[v] == ST_KEEP) continue;
                const ak_vec3 x = c->pos[v];
                vert[l] = (uint32_t)v, start[l] = x;
                L.x[l] = x.x, L.y[l] = x.y, L.z[l] = x.z, L.iso[l] = o->iso[v];
                L.px[l] = L.py[l] = L.pz[l] = 0.0f, L.it[l] = 0.0f;
                L.st[l] = phase == 0 ? (float)ST_KEEP : (float)ST_MOVED;
                live |= 1u << l;
                break;
            }
        }
        if (!live) break;
        const unsigned ended = c->lanes_fn(&fd, &L, live);
        for (unsigned bits = ended; bits; bits &= bits - 1) {
            const unsigned l = (unsigned)ctz64(bits);
            const uint32_t v = vert[l];
            march m = {ak_vec3_make(L.x[l], L.y[l], L.z[l]), start[l], ak_vec3_zero(), 0, (uint8_t)L.st[l]};
            const uint8_t st = march_end(&m, ak_vec3_make(L.gx[l], L.gy[l], L.gz[l]), &c->pos[v], &c->grad[v]);
            if (phase == 0) c->state[v] = st;
            else if (st == ST_STOPPED) c->state[v] = ST_STOPPED;
            live &= ~(1u << l);
        }
    }
}

typedef struct run_task {
    run_ctx* c;
    const uint32_t* list; /* the vertices to visit, or NULL: all */
    size_t begin, end;
    int phase; /* 0 first projection, 1 relax, 2 re-projection, 3 contact */
} run_task;

static void* run_worker(void* arg) {
    run_task* t = (run_task*)arg;
    run_ctx* c = t->c;
    const ak_skin_implicit* o = c->o;
    if (c->lanes_fn && (t->phase == 0 || t->phase == 2)) {
        project_lanes(c, t->list, t->begin, t->end, t->phase);
        return NULL;
    }
    for (size_t i = t->begin; i < t->end; ++i) {
        const size_t v = t->list ? t->list[i] : i;
        if (o->rep[v] != v || !projectable(o->iso[v])) continue;
        if (t->phase == 0) {
            if (rigid_alone(c, v)) continue; /* kept: exactly at its iso-value already */
            c->state[v] = project(c, o->iso[v], &c->pos[v], &c->grad[v], true, c->unchecked_below);
        } else if (t->phase == 1) {
            if (c->state[v] == ST_KEEP) continue;
            uint32_t a = o->adj_start[v], b = o->adj_start[v + 1];
            if (a == b) continue;
            ak_vec3 sum = ak_vec3_zero();
            for (uint32_t e = a; e < b; ++e) sum = ak_vec3_add(sum, c->prev[o->adj[e]]);
            ak_vec3 d = ak_vec3_sub(ak_vec3_scale(sum, 1.0f / (float)(b - a)), c->prev[v]);
            ak_vec3 n = ak_vec3_normalize(c->grad[v]);
            d = ak_vec3_sub(d, ak_vec3_scale(n, ak_vec3_dot(d, n)));
            ak_vec3 q = ak_vec3_add(c->prev[v], ak_vec3_scale(d, 0.5f));
            c->pos[v] = ak_vec3_is_finite(q) ? q : c->prev[v];
        } else if (t->phase == 2) {
            if (c->state[v] == ST_KEEP) continue;
            uint8_t st = project(c, o->iso[v], &c->pos[v], &c->grad[v], false, c->unchecked_below);
            if (st == ST_STOPPED) c->state[v] = ST_STOPPED;
        } else if (t->phase == 3) {
            contact_vertex(c, v, true);
        } else {
            /* phase 4: smoothing of the contact region (half-way to the one-ring centroid of the
             * previous round), then the planes again */
            if (!(c->state[v] & ST_CONTACT)) continue;
            uint32_t a = o->adj_start[v], b = o->adj_start[v + 1];
            if (a == b) continue;
            ak_vec3 sum = ak_vec3_zero();
            for (uint32_t e = a; e < b; ++e) sum = ak_vec3_add(sum, c->prev[o->adj[e]]);
            ak_vec3 q = ak_vec3_lerp(c->prev[v], ak_vec3_scale(sum, 1.0f / (float)(b - a)), 0.5f);
            if (ak_vec3_is_finite(q)) c->pos[v] = q;
            contact_vertex(c, v, false);
        }
    }
    return NULL;
}

/* The projectable welded representatives into order, grouped by part (counting sort; index
 * order within a part); returns their number. counts: joint_count + 1 scratch. */
static size_t order_by_part(const ak_skin_implicit* o, uint32_t* order, uint32_t* counts) {
    const size_t nv = o->vertex_count, nj = o->joint_count;
    memset(counts, 0, (nj + 1) * sizeof(uint32_t));
    for (size_t v = 0; v < nv; ++v)
        if (o->rep[v] == v && projectable(o->iso[v])) ++counts[o->part[v] < nj ? o->part[v] : nj];
    uint32_t at = 0;
    for (size_t j = 0; j <= nj; ++j) {
        const uint32_t n = counts[j];
        counts[j] = at, at += n;
    }
    for (size_t v = 0; v < nv; ++v)
        if (o->rep[v] == v && projectable(o->iso[v])) order[counts[o->part[v] < nj ? o->part[v] : nj]++] = (uint32_t)v;
    return at;
}

static void run_phase(run_ctx* c, int phase, uint32_t threads, const uint32_t* list, size_t n) {
    run_task tasks[64];
    for (uint32_t t = 0; t < threads; ++t) tasks[t] = (run_task){c, list, n * t / threads, n * (t + 1) / threads, phase};
    akp_run_tasks(run_worker, tasks, sizeof tasks[0], threads);
}

ak_result ak_skin_implicit_run(const ak_skin_implicit_job* job) {
    if (!job || !job->implicit || !job->palette.ptr || !job->out_positions.ptr || !job->scratch.ptr)
        return AK_ERR_NULL_ARG;
    const ak_skin_implicit* o = job->implicit;
    if (job->thread_count > 64 || (unsigned)job->simd_limit >= AK_SKIN_SIMD_COUNT) return AK_ERR_BAD_ARG;
    const size_t nv = o->vertex_count;
    if (job->palette.count < o->joint_count || job->out_positions.count < nv ||
        (job->out_normals.ptr && job->out_normals.count < nv) || (job->normals.ptr && job->normals.count < nv) ||
        job->scratch.count < ak_skin_implicit_scratch_size(o, job->palette.count))
        return AK_ERR_SPAN_SMALL;
    unsigned char* base = (unsigned char*)align64((size_t)job->scratch.ptr);
    float* inv = (float*)(void*)base;
    base += align64(o->joint_count * 12 * sizeof(float));
    ak_mat4 probe;
    ak_skin_job dq = {.method = AK_SKIN_DQS, .palette = {&probe, job->palette.count}};
    size_t dq_size = ak_skin_job_scratch_size(&dq);
    unsigned char* dq_scratch = base;
    base += align64(dq_size);
    uint8_t* state = base;
    base += align64(nv);
    ak_vec3* grad = (ak_vec3*)(void*)base;
    base += align64(nv * sizeof(ak_vec3));
    ak_vec3* prev = (ak_vec3*)(void*)base;
    base += align64(nv * sizeof(ak_vec3));
    ak_vec3* dqpos = (ak_vec3*)(void*)base;
    base += align64(nv * sizeof(ak_vec3));
    float* frame = (float*)(void*)base;
    base += align64(o->pair_count * PAIR_FRAME * sizeof(float));
    float* cull = (float*)(void*)base;
    base += align64(o->joint_count * CULL_FLOATS * sizeof(float));
    float* bf = (float*)(void*)base;
    base += align64(o->joint_count * BF_FLOATS * sizeof(float));
    unsigned char* groups = base;
    base += groups_bytes(o);
    uint32_t* list = (uint32_t*)(void*)base;
    base += align64(nv * sizeof(uint32_t));
    uint8_t* flag = base;
    base += align64(nv);
    uint32_t* tris = (uint32_t*)(void*)base;
    base += align64(o->triangle_count * sizeof(uint32_t));
    uint32_t* order = (uint32_t*)(void*)base;
    base += align64(nv * sizeof(uint32_t));
    uint32_t* counts = (uint32_t*)(void*)base;
    base += align64((o->joint_count + 1) * sizeof(uint32_t));
    float* vcache = (float*)(void*)base;
    base += align64(nv * 8 * sizeof(float));
    uint32_t* fold_start = (uint32_t*)(void*)base;
    base += align64((o->joint_count + 1) * sizeof(uint32_t));
    uint32_t* fold_pair = (uint32_t*)(void*)base;
    base += align64(2 * o->pair_count * sizeof(uint32_t));
    uint64_t* mask = (uint64_t*)(void*)base;
    if (!invert_palette(o, job->palette.ptr, inv)) return AK_ERR_BAD_DATA;
    const uint32_t threads = job->thread_count > 1 ? job->thread_count : 1;
    dq = (ak_skin_job){
        .method = AK_SKIN_DQS,
        .influence_count = o->influence_count,
        .palette = job->palette,
        .positions = {o->positions, nv, 0},
        .joints = {o->joints, nv, 0},
        .weights = {o->weights, nv, 0},
        .skip_data_check = true,
        .thread_count = threads,
        .scratch = {dq_scratch, dq_size},
        .out_positions = {job->out_positions.ptr, nv, 0},
    };
    if (job->normals.ptr && job->out_normals.ptr) {
        dq.normals = (ak_cstream){job->normals.ptr, nv, 0};
        dq.out_normals = (ak_stream){job->out_normals.ptr, nv, 0};
    }
    ak_result r = ak_skin_job_run(&dq);
    if (r != AK_OK) return r;
    ak_vec3* pos = job->out_positions.ptr;
    memset(state, 0, nv);
    broad_phase bp;
    if (o->grid_nodes) cull_build(o, cull);
    if (o->grid_nodes) bp_build(o, job->palette.ptr, inv, cull, mask, &bp);
    /* the lane kernel this CPU has, up to the job's simd_limit (with grids and at most 64 bones) */
    unsigned (*lanes_fn)(const akp_implicit_field*, akp_implicit_lanes*, unsigned) = NULL;
    unsigned lanes = 0;
    if (o->grid_nodes && bp.words == 1 && (job->iterations == 0 || job->iterations <= (1u << 20))) {
        const ak_skin_simd level = job->simd_limit == AK_SKIN_SIMD_DEFAULT ? AK_SKIN_SIMD_AVX512 : job->simd_limit;
        if (level >= AK_SKIN_SIMD_AVX512 && akp_skin_have_avx512()) lanes_fn = akp_implicit_march_avx512, lanes = 16;
        else if (level >= AK_SKIN_SIMD_AVX2 && akp_skin_have_avx2()) lanes_fn = akp_implicit_march_avx2, lanes = 8;
    }
    if (o->grid_nodes) {
        bone_frames_build(o, inv, cull, bf);
        const size_t ncell = (size_t)bp.cells * bp.cells * bp.cells;
        uint32_t* cell_group = (uint32_t*)(void*)groups;
        uint32_t* table = (uint32_t*)(void*)(groups + align64(2 * ncell * sizeof(uint32_t)));
        float* group = (float*)(void*)(groups + 2 * align64(2 * ncell * sizeof(uint32_t)));
        uint32_t* group_bone = (uint32_t*)(void*)((unsigned char*)group + align64((size_t)GROUP_CAP * GROUP_FLOATS * sizeof(float)));
        if (lanes_fn) bp.cell_group = NULL, bp.group = NULL, bp.group_bone = NULL; /* no field_eval */
        else groups_build(bf, &bp, cell_group, table, group, group_bone);
    }
    run_ctx c = {o, {o, inv, o->bulge, o->grid_nodes ? &bp : NULL, o->grid_nodes ? bf : NULL}, job->iterations ? job->iterations : 10, pos, prev, grad, state, dqpos, frame, fold_start, fold_pair, NULL, 0, {0}, 0.0f};
    if (lanes_fn) {
        c.lanes_fn = lanes_fn, c.lanes = lanes;
        c.lanes_fd = (akp_implicit_field){o->grid, o->grid_info, bf, inv, BF_FLOATS, o->bulge,
            {bp.lo[0], bp.lo[1], bp.lo[2]}, {bp.inv_cell[0], bp.inv_cell[1], bp.inv_cell[2]}, bp.cells,
            bp.empty ? NULL : bp.mask, (float)c.iterations, ISO_EPS, STOP_COS, o->step_cap, 0.0f};
    }
    memcpy(dqpos, pos, nv * sizeof(ak_vec3));
    /* the projectable representatives grouped by part (counting sort, index order within a
     * part), so that consecutive projections read the same grids (each vertex's projection
     * is independent of the others': the order changes no result) */
    const size_t np = order_by_part(o, order, counts);
    uint32_t rounds = job->relax_rounds == 0 ? 3 : job->relax_rounds == UINT32_MAX ? 0 : job->relax_rounds;
    if (rounds > 64) rounds = 64;
    c.unchecked_below = rounds ? UNCHECKED_EPS : 0.0f;
    run_phase(&c, 0, threads, order, np);
    for (uint32_t k = 0; k < rounds; ++k) {
        memcpy(prev, pos, nv * sizeof(ak_vec3));
        run_phase(&c, 1, threads, order, np);
        c.unchecked_below = k + 1 < rounds ? FLT_MAX : 0.0f;
        run_phase(&c, 2, threads, order, np);
    }
    if (o->pair_count) {
        bool contact = false;
        contact_frames(o, job->palette.ptr, frame);
        fold_lists_build(o, frame, fold_start, fold_pair);
        for (size_t p = 0; p < o->pair_count; ++p) contact = contact || frame[p * PAIR_FRAME + 6] != 0.0f;
        if (contact) {
            /* phase 3 visits the vertices near a folded joint of their part, phase 4 those it
             * touched (only they move there, so prev needs only their copies after the first) */
            size_t nl = 0, nc = 0;
            for (size_t v = 0; v < nv; ++v)
                if (o->rep[v] == v && projectable(o->iso[v]) && near_fold(&c, v)) list[nl++] = (uint32_t)v;
            run_phase(&c, 3, threads, list, nl);
            for (size_t i = 0; i < nl; ++i)
                if (state[list[i]] & ST_CONTACT) list[nc++] = list[i];
            memcpy(prev, pos, nv * sizeof(ak_vec3));
            for (int k = 0; k < CONTACT_SMOOTH; ++k) {
                if (k)
                    for (size_t i = 0; i < nc; ++i) prev[list[i]] = pos[list[i]];
                run_phase(&c, 4, threads, list, nc);
            }
            if (o->closed) keep_volume(&c, prev, list, flag, tris, vcache);
        }
    }
    size_t moved = 0;
    for (size_t v = 0; v < nv; ++v) {
        if (o->rep[v] != v) pos[v] = pos[o->rep[v]];
        else moved += state[v] != ST_KEEP;
    }
    if (job->out_moved) *job->out_moved = moved;
    if (job->out_normals.ptr) {
        /* face normals (welded) where the projection moved a corner of a triangle; elsewhere the
         * DQS-rotated input normals when given */
        ak_vec3* n = job->out_normals.ptr;
        const bool all = job->normals.ptr == NULL;
        for (size_t t = 0; t < o->triangle_count && !all; ++t) {
            const uint32_t* ix = o->indices + 3 * t;
            uint32_t a = o->rep[ix[0]], b = o->rep[ix[1]], cc = o->rep[ix[2]];
            bool moved = (state[a] & 3) == ST_MOVED || (state[a] & 3) == ST_STOPPED || (state[b] & 3) == ST_MOVED ||
                         (state[b] & 3) == ST_STOPPED || (state[cc] & 3) == ST_MOVED || (state[cc] & 3) == ST_STOPPED;
            if (moved) state[a] |= 4, state[b] |= 4, state[cc] |= 4;
        }
        for (size_t v = 0; v < nv; ++v)
            if (all || (state[v] & 4)) n[v] = ak_vec3_zero();
        for (size_t t = 0; t < o->triangle_count; ++t) {
            const uint32_t* ix = o->indices + 3 * t;
            uint32_t a = o->rep[ix[0]], b = o->rep[ix[1]], cc = o->rep[ix[2]];
            if (!all && !((state[a] | state[b] | state[cc]) & 4)) continue;
            ak_vec3 fn = ak_vec3_cross(ak_vec3_sub(pos[b], pos[a]), ak_vec3_sub(pos[cc], pos[a]));
            if (!ak_vec3_is_finite(fn)) continue;
            if (all || (state[a] & 4)) n[a] = ak_vec3_add(n[a], fn);
            if (all || (state[b] & 4)) n[b] = ak_vec3_add(n[b], fn);
            if (all || (state[cc] & 4)) n[cc] = ak_vec3_add(n[cc], fn);
        }
        for (size_t v = 0; v < nv; ++v) {
            if (o->rep[v] != v || !(all || (state[v] & 4))) continue;
            float l = ak_vec3_length(n[v]);
            n[v] = l > 1e-30f && ak_finitef(l) ? ak_vec3_scale(n[v], 1.0f / l) : ak_vec3_make(0, 1, 0);
        }
        for (size_t v = 0; v < nv; ++v)
            if (o->rep[v] != v && (all || (state[o->rep[v]] & 4))) n[v] = n[o->rep[v]];
    }
    return AK_OK;
}
