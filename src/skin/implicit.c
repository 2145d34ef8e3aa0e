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

#define MAX_CAPS 16
#define STOP_COS 0.57357643635f /* cos 55 degrees: the 2014 paper's discontinuity angle */
#define ISO_EPS 1e-4f
#define CAPSULE_AT 12
#define BONE_FLOATS (CAPSULE_AT + 8) /* cx cy cz s | ax ay az b | r sphere2 valid pad |
                                        capsule a(3) b(3) radius pad, bind space */
#define SAMPLE_FLOATS 8 /* x y z alpha | bx by bz pad (normalised coordinates) */

struct ak_skin_implicit {
    ak_allocator alloc;
    size_t arrays_size; /* bytes of the arrays after the struct (the file's payload) */
    size_t vertex_count, triangle_count, joint_count, adj_count, sample_capacity;
    uint32_t influence_count;
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
};

static size_t align64(size_t n) { return (n + 63u) & ~(size_t)63u; }

/* ---- object memory ----------------------------------------------------------------------- */

typedef struct implicit_counts {
    size_t vertex_count, triangle_count, joint_count, adj_count, sample_capacity;
    uint32_t influence_count;
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
              add_bytes(&total, c->joint_count, BONE_FLOATS * 4);
    if (!ok) return NULL;
    unsigned char* mem = (unsigned char*)akp_alloc(alloc, total);
    if (!mem) return NULL;
    memset(mem, 0, total);
    ak_skin_implicit* o = (ak_skin_implicit*)(void*)mem;
    if (alloc) o->alloc = *alloc;
    o->vertex_count = nv, o->triangle_count = c->triangle_count, o->joint_count = c->joint_count;
    o->adj_count = c->adj_count, o->sample_capacity = c->sample_capacity, o->influence_count = c->influence_count;
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

/* Compact-support reparameterisation: t(u) = 1/2 - 15/16 (u - 2u^3/3 + u^5/5), u = d / r. */
static float bone_field(const ak_skin_implicit* o, size_t b, ak_vec3 y, ak_vec3* out_g) {
    float d;
    ak_vec3 g;
    *out_g = ak_vec3_zero();
    if (!bone_distance(o, b, y, &d, &g)) return 0.0f;
    const float r = o->bones[b * BONE_FLOATS + 8];
    float u = d / r;
    if (!(u < 1.0f)) return 0.0f;
    if (u <= -1.0f) return 1.0f;
    float u2 = u * u;
    float t = 0.5f - 0.9375f * (u - u2 * u * (2.0f / 3.0f) + u2 * u2 * u * 0.2f);
    float dt = -0.9375f * (1.0f - u2) * (1.0f - u2) / r;
    *out_g = ak_vec3_scale(g, dt);
    return t;
}

/* Per-joint inverse transforms for one run: 12 floats (3x3 linear part column-major, then the
 * translation); identity when xf is NULL. */
typedef struct field_ctx {
    const ak_skin_implicit* o;
    const float* inv; /* [joint_count * 12] or NULL (bind pose) */
    float bulge;
} field_ctx;

static float field_eval(const field_ctx* c, ak_vec3 x, ak_vec3* out_g) {
    const ak_skin_implicit* o = c->o;
    float f1 = 0.0f, f2 = 0.0f;
    ak_vec3 g1 = ak_vec3_zero(), g2 = ak_vec3_zero();
    for (size_t b = 0; b < o->joint_count; ++b) {
        if (o->bones[b * BONE_FLOATS + 10] == 0.0f) continue;
        ak_vec3 y = x;
        const float* m = c->inv ? c->inv + 12 * b : NULL;
        if (m)
            y = ak_vec3_make(m[0] * x.x + m[3] * x.y + m[6] * x.z + m[9], m[1] * x.x + m[4] * x.y + m[7] * x.z + m[10],
                             m[2] * x.x + m[5] * x.y + m[8] * x.z + m[11]);
        ak_vec3 gy;
        float f = bone_field(o, b, y, &gy);
        if (f <= 0.0f) continue;
        /* gradient in posed space: (M^-1)^T gy */
        ak_vec3 g = m ? ak_vec3_make(m[0] * gy.x + m[1] * gy.y + m[2] * gy.z, m[3] * gy.x + m[4] * gy.y + m[5] * gy.z,
                                     m[6] * gy.x + m[7] * gy.y + m[8] * gy.z)
                      : gy;
        if (f > f1) {
            f2 = f1, g2 = g1;
            f1 = f, g1 = g;
        } else if (f > f2) {
            f2 = f, g2 = g;
        }
    }
    float F = f1;
    ak_vec3 G = g1;
    if (c->bulge > 0.0f && f2 > 0.0f) {
        float l1 = ak_vec3_length(g1), l2 = ak_vec3_length(g2);
        if (l1 > 0.0f && l2 > 0.0f) {
            float w = -ak_vec3_dot(g1, g2) / (l1 * l2);
            if (w > 0.0f) {
                F += c->bulge * w * f2 * f2;
                G = ak_vec3_add(G, ak_vec3_scale(g2, 2.0f * c->bulge * w * f2));
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
    return d;
}

uint64_t ak_skin_implicit_key(const ak_skin_implicit_desc* desc) {
    if (!desc) return 0;
    ak_skin_implicit_desc d = ak_skin_implicit_desc_resolved(desc);
    uint64_t h = 0xcbf29ce484222325ull;
    h = akp_fnv1a(h, "AKIS1", 5);
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

static int cmp_u64_implicit(const void* a, const void* b) {
    uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
    return (x > y) - (x < y);
}

static ak_result check_desc(const ak_skin_implicit_desc* d) {
    if (!d->positions.ptr || !d->indices.ptr || !d->joints.ptr || !d->weights.ptr) return AK_ERR_NULL_ARG;
    if (d->positions.count == 0 || d->indices.count == 0) return AK_ERR_EMPTY;
    if (d->influence_count == 0 || d->influence_count > AK_MAX_INFLUENCES || d->indices.count % 3 ||
        d->samples_per_bone < 8 || d->samples_per_bone > 256 || !(d->support_scale > 0.0f) ||
        !(d->support_scale <= 100.0f) || !(d->bulge <= 10.0f) || d->joint_count == 0 || d->joint_count > 65535 || d->thread_count > 64)
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
    implicit_counts cnt = {nv, nt, jc, uniq, 0, (uint32_t)k};
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
    o = object_alloc(&cnt, alloc);
    if (!o) {
        free(parts);
        r = AK_ERR_NO_MEMORY;
        goto fail;
    }
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
    {
        double rsum = 0.0;
        size_t rn = 0;
        for (size_t b = 0; b < jc; ++b)
            if (o->bones[b * BONE_FLOATS + 10] != 0.0f) rsum += o->bones[b * BONE_FLOATS + 8], ++rn;
        o->step_cap = rn ? (float)(0.5 * rsum / (double)rn) : 0.0f;
        o->bulge = d.bulge > 0.0f ? d.bulge : 0.0f;
        field_ctx fc = {o, NULL, o->bulge};
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
            field_ctx fc = {implicit, inv, implicit->bulge};
            f = field_eval(&fc, x, &g);
        }
        if (inv && inv != stack_inv) free(inv);
    }
    if (out_gradient) *out_gradient = g;
    return f;
}

/* ---- cache file ------------------------------------------------------------------------------
 * "AKIS", u32 version 1, u64 key, u64 counts x5 (vertices, triangles, joints, adjacency,
 * sample capacity), u32 influence count, f32 step cap, f32 bulge, u32 zero, then the arrays
 * exactly as the object holds them (little-endian hosts only: others refuse to read/write). */
#define FILE_HEADER 72

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
    akp_put_u32(h + 4, 1);
    put_u64(h + 8, key);
    put_u64(h + 16, implicit->vertex_count), put_u64(h + 24, implicit->triangle_count);
    put_u64(h + 32, implicit->joint_count), put_u64(h + 40, implicit->adj_count);
    put_u64(h + 48, implicit->sample_capacity);
    akp_put_u32(h + 56, implicit->influence_count);
    akp_put_f32(h + 60, implicit->step_cap), akp_put_f32(h + 64, implicit->bulge);
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
    if (fread(h, 1, FILE_HEADER, f) != FILE_HEADER || memcmp(h, "AKIS", 4) != 0 || akp_get_u32(h + 4) != 1) {
        r = AK_ERR_PARSE;
    } else if (get_u64(h + 8) != key) {
        r = AK_ERR_NOT_FOUND;
    } else {
        implicit_counts c = {get_u64(h + 16), get_u64(h + 24), get_u64(h + 32), get_u64(h + 40), get_u64(h + 48),
                             akp_get_u32(h + 56)};
        if (c.vertex_count == 0 || c.vertex_count > (1u << 24) || c.triangle_count > (1u << 26) ||
            c.joint_count == 0 || c.joint_count > 65535 || c.adj_count > 6 * c.triangle_count ||
            c.sample_capacity > 256 * c.joint_count || c.influence_count == 0 ||
            c.influence_count > AK_MAX_INFLUENCES) {
            r = AK_ERR_PARSE;
        } else if (!(o = object_alloc(&c, alloc))) {
            r = AK_ERR_NO_MEMORY;
        } else {
            unsigned char* arrays = (unsigned char*)o + akp_align16(sizeof(ak_skin_implicit));
            o->step_cap = akp_get_f32(h + 60), o->bulge = akp_get_f32(h + 64);
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

size_t ak_skin_implicit_scratch_size(const ak_skin_implicit* implicit, size_t palette_count) {
    if (!implicit) return 0;
    ak_mat4 probe;
    ak_skin_job dq = {.method = AK_SKIN_DQS, .palette = {&probe, palette_count}};
    size_t nv = implicit->vertex_count;
    return 64 + align64(implicit->joint_count * 12 * sizeof(float)) + align64(ak_skin_job_scratch_size(&dq)) +
           align64(nv) + 2 * align64(nv * sizeof(ak_vec3));
}

enum { ST_KEEP = 0, ST_MOVED = 1, ST_STOPPED = 2 };

typedef struct run_ctx {
    const ak_skin_implicit* o;
    field_ctx fc;
    uint32_t iterations;
    ak_vec3* pos;
    ak_vec3* prev;
    ak_vec3* grad;
    uint8_t* state;
} run_ctx;

/* Newton steps from *p towards the vertex's iso-value; returns the state. */
static uint8_t project(const run_ctx* c, float iso, ak_vec3* p, ak_vec3* out_g, bool first) {
    ak_vec3 g, gprev = ak_vec3_zero();
    ak_vec3 x = *p;
    uint8_t st = first ? ST_KEEP : ST_MOVED;
    for (uint32_t it = 0;; ++it) {
        float F = field_eval(&c->fc, x, &g);
        float e = iso - F;
        if (fabsf(e) < ISO_EPS || it == c->iterations) break;
        float gl2 = ak_vec3_length_sq(g);
        if (!(gl2 > 1e-20f)) break;
        if (it > 0 && ak_vec3_dot(g, gprev) < STOP_COS * sqrtf(gl2 * ak_vec3_length_sq(gprev))) {
            st = ST_STOPPED; /* gradient discontinuity: a contact surface */
            break;
        }
        ak_vec3 step = ak_vec3_scale(g, e / gl2);
        float sl = ak_vec3_length(step);
        if (sl > c->o->step_cap) step = ak_vec3_scale(step, c->o->step_cap / sl);
        x = ak_vec3_add(x, step);
        gprev = g;
        if (st == ST_KEEP) st = ST_MOVED;
    }
    if (!ak_vec3_is_finite(x) || !ak_vec3_is_finite(g)) { /* never NaN out: keep the start */
        x = *p;
        g = ak_vec3_zero();
        st = ST_STOPPED;
    }
    *p = x;
    *out_g = g;
    return st;
}

static bool projectable(float iso) { return iso > 0.02f && iso < 0.98f; }

typedef struct run_task {
    run_ctx* c;
    size_t begin, end;
    int phase; /* 0 first projection, 1 relax, 2 re-projection */
} run_task;

static void* run_worker(void* arg) {
    run_task* t = (run_task*)arg;
    run_ctx* c = t->c;
    const ak_skin_implicit* o = c->o;
    for (size_t v = t->begin; v < t->end; ++v) {
        if (o->rep[v] != v || !projectable(o->iso[v])) continue;
        if (t->phase == 0) {
            c->state[v] = project(c, o->iso[v], &c->pos[v], &c->grad[v], true);
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
        } else {
            if (c->state[v] == ST_KEEP) continue;
            uint8_t st = project(c, o->iso[v], &c->pos[v], &c->grad[v], false);
            if (st == ST_STOPPED) c->state[v] = ST_STOPPED;
        }
    }
    return NULL;
}

static void run_phase(run_ctx* c, int phase, uint32_t threads) {
    run_task tasks[64];
    pthread_t ids[64];
    bool started[64] = {false};
    size_t n = c->o->vertex_count;
    for (uint32_t t = 0; t < threads; ++t)
        tasks[t] = (run_task){c, n * t / threads, n * (t + 1) / threads, phase};
    for (uint32_t t = 1; t < threads; ++t) started[t] = pthread_create(&ids[t], NULL, run_worker, &tasks[t]) == 0;
    run_worker(&tasks[0]);
    for (uint32_t t = 1; t < threads; ++t) {
        if (started[t]) pthread_join(ids[t], NULL);
        else run_worker(&tasks[t]);
    }
}

ak_result ak_skin_implicit_run(const ak_skin_implicit_job* job) {
    if (!job || !job->implicit || !job->palette.ptr || !job->out_positions.ptr || !job->scratch.ptr)
        return AK_ERR_NULL_ARG;
    const ak_skin_implicit* o = job->implicit;
    if (job->thread_count > 64) return AK_ERR_BAD_ARG;
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
    run_ctx c = {o, {o, inv, o->bulge}, job->iterations ? job->iterations : 10, pos, prev, grad, state};
    run_phase(&c, 0, threads);
    uint32_t rounds = job->relax_rounds == 0 ? 3 : job->relax_rounds == UINT32_MAX ? 0 : job->relax_rounds;
    if (rounds > 64) rounds = 64;
    for (uint32_t k = 0; k < rounds; ++k) {
        memcpy(prev, pos, nv * sizeof(ak_vec3));
        run_phase(&c, 1, threads);
        run_phase(&c, 2, threads);
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
