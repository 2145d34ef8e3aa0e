/* Volumetric (soft-tissue) skinning: a tetrahedral lattice inside the mesh, kinematic nodes
 * around the bones, flesh simulated by XPBD with the stable Neo-Hookean constraints of Macklin
 * & Mueller 2021. See softskin.h. */
#include <animkit/softskin.h>

#include <math.h>
#include <pthread.h> /* thread_count > 1 */

#include "skin_internal.h"

/* The AVX2 tet solve: x86-64 GCC/clang without AK_NO_SIMD, chosen at run time. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#define SOFT_SIMD 1
#include <immintrin.h>
#else
#define SOFT_SIMD 0
#endif

#define SOFT_MAX_COLORS 128u
#define SOFT_INFLUENCES 4u
#define SOFT_NODE_PLANES 4u
#define SOFT_NODES_PER_THREAD 4096u           /* fewer nodes per thread: fewer threads */
#define SOFT_MAX_CUT_BONES 1024u              /* more bones: limbs are not kept apart */
#define SOFT_PART_UNSET (UINT32_MAX - 1u)
/* The cone rule (release_nodes): 0.40-0.48 give the elbow 0 pairs at 130, 140 and 150 deg
 * (0.35: 25 pairs at 150; 0.5: 2 at 130), docs/softskin.md */
#define SOFT_RELEASE_CONE 0.44f     /* sin of the release cone's half-angle about a joint plane */
#define SOFT_RELEASE_BEND_COS 0.0f  /* released only where the bones part by more than 90 deg */
/* a released kinematic node is tied to its skinned position by a zero-length spring of this
 * natural frequency (rad/s; XPBD, one projection per substep after the tets). Untied, the
 * forearm's 22 released nodes of CesiumMan's elbow held at 140 deg slid up to 0.29 m from their
 * skinned positions over 20 held frames and the held elbow kept 1.8e-3 of its bending energy
 * after 1 s. 20 and 30 pass every flexion; 40 gives the elbow at 150 deg 14 pairs
 * (docs/softskin.md) */
#ifndef SOFT_TETHER_OMEGA
#define SOFT_TETHER_OMEGA 30.0f
#endif
/* cubes: a node of a part beyond a joint's two bones (the buttock, the heel) takes the joint's
 * plane when its skinned position lies this close to a skinned node of the other side. Measured
 * on CesiumMan's knees (docs/softskin.md): 1.5 left 54 pairs at the left knee's 150 deg, 2 left
 * 26 at 140, 2.5 left 35 at 150; 3 to 5 left none, but from 3.5 on the left knee at 150 deg
 * lost 1.02% of the enclosed volume (0.85% at 3): 3 is the edge of a narrow window, not a
 * margin */
#define SOFT_CONTACT_REACH 3.0f
/* A bone (kinematic) node of the parts beyond a joint's two bones, gated as above, is let go by
 * degrees from SOFT_LET_GO cubes of the joint's plane (its skinned position): simulated, tied to
 * its skinned position by a spring of SOFT_TETHER_OMEGA / (1 - f)^2 rad/s, f rising linearly from
 * 0 at half a cube (where it was let go at once before, with the plain tether) to 1 at
 * SOFT_LET_GO (kinematic). Let go at once, the pelvis's bone nodes behind CesiumMan's buttock
 * were freed in the last frame of a knee's fold to 150 deg while the knee's plane pressed the
 * buttock's flesh against them: the strain stored against them threw them forward at 7 m/s
 * and the held flesh's kinetic energy rose from 8 to 33 J within four substeps (54-59 J at the
 * step's end). From 2, 3 or 4 cubes, the spring's rate 1 / (1 - f)^0.5, 1 or 2: 30-36 J; the
 * last held the pose best (docs/softskin.md) */
#define SOFT_LET_GO 3.0f

struct ak_skin_soft {
    ak_allocator alloc;
    size_t node_count, tet_count, kin_count, vertex_count, bone_count;
    size_t cut_cells;       /* cells dropped to keep limbs apart */
    float mu, lambda, damping, jiggle_damping;
    uint32_t substeps;
    uint16_t max_joint;
    ak_vec3* rest;          /* [node] */
    uint8_t* kinematic;     /* [node] */
    float* mass;            /* [node] lumped */
    float* inv_mass;        /* [node] 0 for kinematic */
    uint16_t* node_joints;  /* [node * 4] */
    float* node_weights;    /* [node * 4] */
    uint32_t* tets;         /* [4 * tet], sorted by colour */
    float* dm_inv;          /* [9 * tet] column-major inverse rest edge matrix */
    float* dm_soa;          /* [9 * tet]: entry i of tet q at i * tet_count + q (the SIMD solve's loads) */
    uint32_t* tets_soa;     /* [4 * tet]: node k of tet q at k * tet_count + q */
    float* volume;          /* [tet] rest volume */
    uint32_t color_count;
    uint32_t* color_start;  /* [color_count + 1] */
    uint32_t* embed_tet;    /* [vertex] */
    float* embed_bary;      /* [4 * vertex] */
    ak_skin_bone* bones;    /* [bone] */
    float* contact_radius;  /* [bone] median distance of the bone's vertices (0: owns none) */
    float* core_radius;     /* [bone] kinematic capsule radius (at least 1.2 cubes) */
    float* collide_radius;  /* [bone] collider radius: bone_radius x contact_radius */
    uint64_t* collide;      /* [node * collide_words]: bit b -> node collides with bone b */
    size_t collide_words;
    uint32_t plane_count;
    uint32_t* planes;       /* [2 * plane]: parent bone, child bone meeting at a joint */
    int32_t* node_planes;   /* [node * SOFT_NODE_PLANES]: +(p + 1) parent side, -(p + 1) child
                               side, 0 none */
    /* contact beyond a joint's two bones at a deep bend (release_nodes) */
    float cell;             /* lattice cube edge */
    uint8_t* plane_bent0;   /* [plane] 1: the two bones part by more than 90 deg at the bind pose */
    ak_vec3* plane_bisector; /* [plane] the bind pose's unit bisector of the two bones' directions
                                (plane_normal, release_nodes); zero where they meet nearly
                                antiparallel (|sum of the unit directions| <= 0.05) */
    uint32_t* xnode_start;  /* [plane + 1] ranges of xnode */
    int32_t* xnode;         /* +(n + 1) parent side, -(n + 1) child side: a node of a part beyond
                               the joint's two bones (the hips, the foot), gated each step */
    uint32_t* snode_start;  /* [2 * plane + 1] ranges of snode: 2p the nodes of plane p's parent
                               side, 2p + 1 those of its child side's parts beyond the lower bone */
    uint32_t* snode;        /* node indices */
};

/* ---- small helpers -------------------------------------------------------------------- */

static bool mat3_inverse(const float m[9], float out[9], float* out_det) {
    /* column-major m: m[r + 3c] */
    double a = m[0], b = m[3], c = m[6], d = m[1], e = m[4], f = m[7], g = m[2], h = m[5], i = m[8];
    double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    double det = a * A + b * B + c * C;
    *out_det = (float)det;
    if (!(fabs(det) > 1e-30)) return false;
    double inv = 1.0 / det;
    out[0] = (float)(A * inv);
    out[1] = (float)(B * inv);
    out[2] = (float)(C * inv);
    out[3] = (float)(-(b * i - c * h) * inv);
    out[4] = (float)((a * i - c * g) * inv);
    out[5] = (float)(-(a * h - b * g) * inv);
    out[6] = (float)((b * f - c * e) * inv);
    out[7] = (float)(-(a * f - c * d) * inv);
    out[8] = (float)((a * e - b * d) * inv);
    return true;
}

/* Barycentrics of p in the tet with rest origin x0 and inverse edge matrix dmi. */
static void tet_bary(ak_vec3 x0, const float dmi[9], ak_vec3 p, float out[4]) {
    ak_vec3 r = ak_vec3_sub(p, x0);
    float b1 = dmi[0] * r.x + dmi[3] * r.y + dmi[6] * r.z;
    float b2 = dmi[1] * r.x + dmi[4] * r.y + dmi[7] * r.z;
    float b3 = dmi[2] * r.x + dmi[5] * r.y + dmi[8] * r.z;
    out[0] = 1.0f - b1 - b2 - b3;
    out[1] = b1;
    out[2] = b2;
    out[3] = b3;
}

static float min4(const float b[4]) { return ak_minf(ak_minf(b[0], b[1]), ak_minf(b[2], b[3])); }

static uint32_t uf_find(uint32_t* p, uint32_t x) {
    while (p[x] != x) {
        p[x] = p[p[x]];
        x = p[x];
    }
    return x;
}

static int cmp_float(const void* a, const void* b) {
    float x = *(const float*)a, y = *(const float*)b;
    return (x > y) - (x < y);
}

static ak_vec3 lbs_node(const ak_skin_soft* s, size_t n, const ak_mat4* palette, size_t palette_count) {
    ak_vec3 p = ak_vec3_zero();
    for (uint32_t k = 0; k < SOFT_INFLUENCES; ++k) {
        float w = s->node_weights[n * SOFT_INFLUENCES + k];
        if (w == 0.0f) continue;
        size_t j = s->node_joints[n * SOFT_INFLUENCES + k];
        if (j >= palette_count) j = palette_count - 1;
        p = ak_vec3_madd(p, ak_mat4_transform_point(palette[j], s->rest[n]), w);
    }
    return p;
}

/* ---- public: desc --------------------------------------------------------------------- */

ak_skin_soft_desc ak_skin_soft_desc_resolved(const ak_skin_soft_desc* desc) {
    ak_skin_soft_desc d;
    if (desc) d = *desc;
    else memset(&d, 0, sizeof d);
    if (d.resolution == 0) d.resolution = 32;
    if (d.youngs_modulus == 0.0f) d.youngs_modulus = 5e4f;
    if (d.poisson_ratio == 0.0f) d.poisson_ratio = 0.499f;
    if (d.density == 0.0f) d.density = 1000.0f;
    if (d.damping == 0.0f) d.damping = 0.1f;
    if (d.substeps == 0) d.substeps = 40;
    if (d.bone_radius == 0.0f) d.bone_radius = 0.5f;
    if (d.jiggle_damping == 0.0f) d.jiggle_damping = 5.0f;
    if (d.joint_zone == 0.0f) d.joint_zone = 1.5f;
    if (d.memory_budget == 0) d.memory_budget = (size_t)512 << 20;
    return d;
}

void ak_skin_soft_destroy(ak_skin_soft* s) {
    if (!s) return;
    const ak_allocator* a = &s->alloc;
    akp_free(a, s->rest);
    akp_free(a, s->kinematic);
    akp_free(a, s->mass);
    akp_free(a, s->inv_mass);
    akp_free(a, s->node_joints);
    akp_free(a, s->node_weights);
    akp_free(a, s->tets);
    akp_free(a, s->dm_inv);
    akp_free(a, s->dm_soa);
    akp_free(a, s->tets_soa);
    akp_free(a, s->volume);
    akp_free(a, s->color_start);
    akp_free(a, s->embed_tet);
    akp_free(a, s->embed_bary);
    akp_free(a, s->bones);
    akp_free(a, s->contact_radius);
    akp_free(a, s->core_radius);
    akp_free(a, s->collide_radius);
    akp_free(a, s->collide);
    akp_free(a, s->planes);
    akp_free(a, s->node_planes);
    akp_free(a, s->plane_bent0);
    akp_free(a, s->plane_bisector);
    akp_free(a, s->xnode_start);
    akp_free(a, s->xnode);
    akp_free(a, s->snode_start);
    akp_free(a, s->snode);
    ak_allocator copy = s->alloc;
    akp_free(&copy, s);
}

/* ---- create --------------------------------------------------------------------------- */

typedef struct crossing {
    float x;
    int sign;
} crossing;

static ak_result check_desc(const ak_skin_soft_desc* d) {
    if (!d->positions.ptr || !d->indices.ptr || !d->joints.ptr || !d->weights.ptr || !d->bones.ptr) return AK_ERR_NULL_ARG;
    if (d->positions.count == 0 || d->indices.count == 0 || d->bones.count == 0) return AK_ERR_EMPTY;
    if (d->indices.count % 3 || d->influence_count == 0 || d->influence_count > AK_MAX_INFLUENCES ||
        d->positions.count > ((size_t)1 << 31) || d->bones.count > 65535)
        return AK_ERR_BAD_ARG;
    if (d->resolution < 2 || d->resolution > 256 || !(d->youngs_modulus > 0.0f) || !isfinite(d->youngs_modulus) ||
        !(d->poisson_ratio > 0.0f && d->poisson_ratio <= 0.4999f) || !(d->density > 0.0f) || !isfinite(d->density) ||
        !isfinite(d->damping) || !isfinite(d->jiggle_damping) || d->substeps > 1000 || !(d->bone_radius > 0.0f && d->bone_radius <= 1.0f) ||
        !(d->joint_zone > 0.0f && d->joint_zone <= 100.0f))
        return AK_ERR_BAD_ARG;
    size_t wn = d->positions.count * d->influence_count;
    if (d->joints.count < wn || d->weights.count < wn) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < d->indices.count; ++i)
        if (d->indices.ptr[i] >= d->positions.count) return AK_ERR_BAD_INDEX;
    for (size_t v = 0; v < d->positions.count; ++v)
        if (!ak_vec3_is_finite(d->positions.ptr[v])) return AK_ERR_BAD_DATA;
    for (size_t b = 0; b < d->bones.count; ++b)
        if (!ak_vec3_is_finite(d->bones.ptr[b].head) || !ak_vec3_is_finite(d->bones.ptr[b].tail)) return AK_ERR_BAD_DATA;
    for (size_t i = 0; i < wn; ++i)
        if (!(d->weights.ptr[i] >= 0.0f) || !isfinite(d->weights.ptr[i])) return AK_ERR_BAD_WEIGHTS;
    return AK_OK;
}

/* Temporary arrays of create, freed together. */
typedef struct build_tmp {
    uint8_t* keep;         /* [cells] */
    uint32_t* col_count;   /* [columns + 1] */
    crossing* cross;       /* [crossings] */
    uint32_t* grid_node;   /* [grid nodes] -> node index or UINT32_MAX */
    uint32_t* cell_tet;    /* [cells] first tet of a kept cell (pre-colour order) */
    uint32_t* tets;        /* [4 * tets] pre-colour */
    uint32_t* color;       /* [tets] */
    uint64_t* used;        /* [node * 2] colour masks */
    uint32_t* perm;        /* [tets] new index of old tet */
    uint32_t* uf;          /* [node] */
    uint8_t* comp_kin;     /* [node] */
    float* dist;           /* [vertex] */
    uint32_t* owner;       /* [vertex] bone of a vertex */
    uint32_t* grid_part;   /* [grid nodes] nearest owning bone, UINT32_MAX unset */
    uint32_t* node_part;   /* [node] the same per lattice node */
    uint64_t* adjacent;    /* [bone * words] bit b: at most two steps apart */
} build_tmp;

static void tmp_free(const ak_allocator* a, build_tmp* t) {
    akp_free(a, t->keep);
    akp_free(a, t->col_count);
    akp_free(a, t->cross);
    akp_free(a, t->grid_node);
    akp_free(a, t->cell_tet);
    akp_free(a, t->tets);
    akp_free(a, t->color);
    akp_free(a, t->used);
    akp_free(a, t->perm);
    akp_free(a, t->uf);
    akp_free(a, t->comp_kin);
    akp_free(a, t->dist);
    akp_free(a, t->owner);
    akp_free(a, t->grid_part);
    akp_free(a, t->node_part);
    akp_free(a, t->adjacent);
}

/* The owning bone (contact_radius > 0) nearest to p; UINT32_MAX when none owns vertices. */
static uint32_t nearest_part(const ak_skin_soft* s, ak_vec3 p) {
    float best = INFINITY;
    uint32_t part = UINT32_MAX;
    for (size_t b = 0; b < s->bone_count; ++b) {
        if (!(s->contact_radius[b] > 0.0f)) continue;
        float d2 = akp_segment_dist_sq(p, s->bones[b].head, s->bones[b].tail, NULL);
        if (d2 < best) {
            best = d2;
            part = (uint32_t)b;
        }
    }
    return part;
}

static bool parts_adjacent(const build_tmp* t, size_t words, uint32_t a, uint32_t b) {
    if (a == b || a >= SOFT_PART_UNSET || b >= SOFT_PART_UNSET || !t->adjacent) return true;
    return (t->adjacent[(size_t)a * words + b / 64] >> (b % 64)) & 1u;
}

/* Whether every node of a tet belongs to a part that shares a joint with bone `part`. */
static bool tet_fits(const build_tmp* t, size_t words, const uint32_t* tt, uint32_t part) {
    if (!t->node_part) return true;
    for (int c = 0; c < 4; ++c)
        if (!parts_adjacent(t, words, t->node_part[tt[c]], part)) return false;
    return true;
}

/* Kuhn split of a cube: the 6 monotone paths from corner 0 to corner 7 (bits x=1, y=2, z=4). */
static const uint8_t kuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

ak_result ak_skin_soft_create(const ak_skin_soft_desc* desc_in, const ak_allocator* alloc, ak_skin_soft** out_soft) {
    if (out_soft) *out_soft = NULL;
    if (!desc_in || !out_soft) return AK_ERR_NULL_ARG;
    if (alloc && ((alloc->alloc == NULL) != (alloc->free == NULL))) return AK_ERR_BAD_ARG;
    const ak_skin_soft_desc d = ak_skin_soft_desc_resolved(desc_in);
    ak_result r = check_desc(&d);
    if (r != AK_OK) return r;
    const size_t nv = d.positions.count, ntri = d.indices.count / 3, nb = d.bones.count;
    const ak_vec3* P = d.positions.ptr;

    /* grid */
    ak_vec3 lo, hi;
    ak_points_bounds(d.positions, &lo, &hi);
    ak_vec3 ext = ak_vec3_sub(hi, lo);
    float longest = ak_maxf(ext.x, ak_maxf(ext.y, ext.z));
    if (!(longest > 0.0f)) return AK_ERR_BAD_DATA;
    const float h = longest / (float)d.resolution;
    size_t dim[3];
    float e3[3] = {ext.x, ext.y, ext.z}, lo3[3] = {lo.x, lo.y, lo.z}, org[3];
    for (int a = 0; a < 3; ++a) {
        size_t n = (size_t)ceilf(e3[a] / h * 0.9999f);
        if (n < 1) n = 1;
        if (n > 256) n = 256;
        dim[a] = n;
        org[a] = lo3[a] - 0.5f * ((float)n * h - e3[a]);
    }
    const size_t nx = dim[0], ny = dim[1], nz = dim[2];
    const size_t cells = nx * ny * nz, gnodes = (nx + 1) * (ny + 1) * (nz + 1), cols = ny * nz;
    /* budget: temporaries and the worst case (every cell kept) of the result */
    size_t budget_need = cells * (1 + 4 + 6 * (16 + 4 + 4 + 36 + 4 + 4 + 36 + 16)) + gnodes * (4 + 12 + 1 + 8 + 4 + 32 + 16 + 4 + 1 + 8 * ((nb + 63) / 64)) +
                         (cols + 1) * 4 + nv * (4 + 16 + 4 + 4) + nb * 64 + gnodes * 8 +
                         (nb <= SOFT_MAX_CUT_BONES ? 2 * nb * ((nb + 63) / 64) * 8 : 0);
    if (budget_need > d.memory_budget) return AK_ERR_BUDGET;

    const ak_allocator* A = alloc;
    build_tmp t;
    memset(&t, 0, sizeof t);
    ak_skin_soft* s = (ak_skin_soft*)akp_calloc(A, sizeof(ak_skin_soft));
    if (!s) return AK_ERR_NO_MEMORY;
    if (alloc) s->alloc = *alloc;
    s->vertex_count = nv;
    s->bone_count = nb;
    s->substeps = d.substeps;
    s->damping = d.damping > 0.0f ? d.damping : 0.0f;
    s->jiggle_damping = d.jiggle_damping > 0.0f ? d.jiggle_damping : 0.0f;
    s->mu = d.youngs_modulus / (2.0f * (1.0f + d.poisson_ratio));
    s->lambda = d.youngs_modulus * d.poisson_ratio / ((1.0f + d.poisson_ratio) * (1.0f - 2.0f * d.poisson_ratio));
#define SOFT_ALLOC(ptr, type, n)                                      \
    do {                                                              \
        (ptr) = (type*)akp_calloc(A, (size_t)(n) * sizeof(type));     \
        if (!(ptr)) {                                                 \
            r = AK_ERR_NO_MEMORY;                                     \
            goto fail;                                                \
        }                                                             \
    } while (0)

    /* 0. bones: flesh radius = median distance of the vertices each bone owns */
    SOFT_ALLOC(s->bones, ak_skin_bone, nb);
    SOFT_ALLOC(s->contact_radius, float, nb);
    SOFT_ALLOC(s->core_radius, float, nb);
    SOFT_ALLOC(s->collide_radius, float, nb);
    memcpy(s->bones, d.bones.ptr, nb * sizeof(ak_skin_bone));
    for (size_t b = 0; b < nb; ++b)
        if (s->bones[b].joint_index > s->max_joint) s->max_joint = s->bones[b].joint_index;
    SOFT_ALLOC(t.dist, float, nv);
    SOFT_ALLOC(t.owner, uint32_t, nv);
    for (size_t v = 0; v < nv; ++v) {
        const uint16_t* jv = &d.joints.ptr[v * d.influence_count];
        const float* wv = &d.weights.ptr[v * d.influence_count];
        uint16_t dom = jv[0];
        float wmax = wv[0];
        for (uint32_t k = 1; k < d.influence_count; ++k)
            if (wv[k] > wmax) {
                wmax = wv[k];
                dom = jv[k];
            }
        float best = INFINITY;
        t.owner[v] = UINT32_MAX;
        for (size_t b = 0; b < nb; ++b) {
            if (s->bones[b].joint_index != dom) continue;
            float dd = akp_segment_dist_sq(P[v], s->bones[b].head, s->bones[b].tail, NULL);
            if (dd < best) {
                best = dd;
                t.owner[v] = (uint32_t)b;
            }
        }
    }
    for (size_t b = 0; b < nb; ++b) {
        size_t cnt = 0;
        for (size_t v = 0; v < nv; ++v)
            if (t.owner[v] == b) t.dist[cnt++] = sqrtf(akp_segment_dist_sq(P[v], s->bones[b].head, s->bones[b].tail, NULL));
        if (cnt == 0) continue;
        qsort(t.dist, cnt, sizeof(float), cmp_float);
        s->contact_radius[b] = t.dist[cnt / 2];
    }
    s->cell = h;

    /* 1. inside test: per column of cell centres, signed crossings of a ray along +X */
    SOFT_ALLOC(t.keep, uint8_t, cells);
    SOFT_ALLOC(t.col_count, uint32_t, cols + 1);
    /* a tiny irrational offset keeps rays off the vertices and edges of regular meshes */
    const float jy = 0.5f + 0.000137f * 3.14159265f, jz = 0.5f + 0.000173f * 2.71828183f;
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) {
            size_t total = 0;
            for (size_t c = 0; c < cols; ++c) {
                size_t k = t.col_count[c];
                t.col_count[c] = (uint32_t)total;
                total += k;
            }
            t.col_count[cols] = (uint32_t)total;
            if (total * sizeof(crossing) > d.memory_budget) {
                r = AK_ERR_BUDGET;
                goto fail;
            }
            if (total) SOFT_ALLOC(t.cross, crossing, total);
        }
        for (size_t f = 0; f < ntri; ++f) {
            ak_vec3 a = P[d.indices.ptr[3 * f]], b = P[d.indices.ptr[3 * f + 1]], c = P[d.indices.ptr[3 * f + 2]];
            float ymin = ak_minf(a.y, ak_minf(b.y, c.y)), ymax = ak_maxf(a.y, ak_maxf(b.y, c.y));
            float zmin = ak_minf(a.z, ak_minf(b.z, c.z)), zmax = ak_maxf(a.z, ak_maxf(b.z, c.z));
            long j0 = (long)floorf((ymin - org[1]) / h - jy) + 1, j1 = (long)floorf((ymax - org[1]) / h - jy);
            long k0 = (long)floorf((zmin - org[2]) / h - jz) + 1, k1 = (long)floorf((zmax - org[2]) / h - jz);
            if (j0 < 0) j0 = 0;
            if (k0 < 0) k0 = 0;
            if (j1 >= (long)ny) j1 = (long)ny - 1;
            if (k1 >= (long)nz) k1 = (long)nz - 1;
            float nxs = (b.y - a.y) * (c.z - a.z) - (b.z - a.z) * (c.y - a.y);
            if (nxs == 0.0f) continue;
            for (long k = k0; k <= k1; ++k)
                for (long j = j0; j <= j1; ++j) {
                    float py = org[1] + ((float)j + jy) * h, pz = org[2] + ((float)k + jz) * h;
                    /* 2D edge functions in the yz plane */
                    float ea = (b.y - py) * (c.z - pz) - (b.z - pz) * (c.y - py);
                    float eb = (c.y - py) * (a.z - pz) - (c.z - pz) * (a.y - py);
                    float ec = (a.y - py) * (b.z - pz) - (a.z - pz) * (b.y - py);
                    bool in = (ea >= 0 && eb >= 0 && ec >= 0) || (ea <= 0 && eb <= 0 && ec <= 0);
                    float sum = ea + eb + ec;
                    if (!in || sum == 0.0f) continue;
                    size_t col = (size_t)k * ny + (size_t)j;
                    if (pass == 0) {
                        t.col_count[col]++;
                    } else {
                        float x = (ea * a.x + eb * b.x + ec * c.x) / sum;
                        t.cross[t.col_count[col]++] = (crossing){x, nxs > 0.0f ? 1 : -1};
                    }
                }
        }
        if (pass == 1) /* fill advanced each start to the next column's start: shift back */
            for (size_t c = cols; c > 0; --c) t.col_count[c] = t.col_count[c - 1];
    }
    t.col_count[0] = 0;
    for (size_t k = 0; k < nz; ++k)
        for (size_t j = 0; j < ny; ++j) {
            size_t col = k * ny + j;
            for (size_t i = 0; i < nx; ++i) {
                float cx = org[0] + ((float)i + 0.5f) * h;
                int w = 0;
                for (uint32_t q = t.col_count[col]; q < t.col_count[col + 1]; ++q)
                    if (t.cross[q].x > cx) w += t.cross[q].sign;
                if (w != 0) t.keep[(k * ny + j) * nx + i] = 1;
            }
        }
    /* cells holding a surface vertex */
    for (size_t v = 0; v < nv; ++v) {
        size_t ci[3];
        float p3[3] = {P[v].x, P[v].y, P[v].z};
        for (int a = 0; a < 3; ++a) {
            float f = floorf((p3[a] - org[a]) / h);
            ci[a] = f < 0.0f ? 0 : (size_t)f >= dim[a] ? dim[a] - 1 : (size_t)f;
        }
        t.keep[(ci[2] * ny + ci[1]) * nx + ci[0]] = 1;
    }

    /* 1b. keep distinct limbs apart: each corner of a kept cell belongs to its nearest owning
     * bone (its part); a cell with corners of two parts more than two steps apart along the
     * skeleton (the two thighs, a hanging forearm and the chest) is dropped, so the lattice
     * does not bridge a gap between limbs that one cube spans. One step: two bones that meet
     * at an end or belong to the same joint. */
#define GRID(i, j, k) ((((k) * (ny + 1)) + (j)) * (nx + 1) + (i))
    const size_t adj_words = (nb + 63) / 64;
    if (!d.join_distant_parts && nb <= SOFT_MAX_CUT_BONES) {
        SOFT_ALLOC(t.adjacent, uint64_t, nb * adj_words);
        const float tol = 1e-4f * longest;
        for (size_t b1 = 0; b1 < nb; ++b1)
            for (size_t b2 = 0; b2 < nb; ++b2) {
                const ak_skin_bone *u = &s->bones[b1], *w = &s->bones[b2];
                bool adj = b1 == b2 || u->joint_index == w->joint_index || ak_vec3_distance(u->head, w->head) <= tol ||
                           ak_vec3_distance(u->head, w->tail) <= tol || ak_vec3_distance(u->tail, w->head) <= tol ||
                           ak_vec3_distance(u->tail, w->tail) <= tol;
                if (adj) t.adjacent[b1 * adj_words + b2 / 64] |= (uint64_t)1 << (b2 % 64);
            }
        /* two steps along the skeleton: a point bone at a toe and the shin, the thigh and the
         * belly are together; the two thighs (three steps through the pelvis) are not */
        uint64_t* one = (uint64_t*)akp_alloc(A, nb * adj_words * sizeof(uint64_t));
        if (!one) {
            r = AK_ERR_NO_MEMORY;
            goto fail;
        }
        memcpy(one, t.adjacent, nb * adj_words * sizeof(uint64_t));
        for (size_t b1 = 0; b1 < nb; ++b1)
            for (size_t b2 = 0; b2 < nb; ++b2)
                if ((one[b1 * adj_words + b2 / 64] >> (b2 % 64)) & 1u)
                    for (size_t w = 0; w < adj_words; ++w) t.adjacent[b1 * adj_words + w] |= one[b2 * adj_words + w];
        akp_free(A, one);
        SOFT_ALLOC(t.grid_part, uint32_t, gnodes);
        for (size_t g = 0; g < gnodes; ++g) t.grid_part[g] = SOFT_PART_UNSET;
        for (size_t k = 0; k < nz; ++k)
            for (size_t j = 0; j < ny; ++j)
                for (size_t i = 0; i < nx; ++i) {
                    size_t cell = (k * ny + j) * nx + i;
                    if (!t.keep[cell]) continue;
                    uint32_t parts[8];
                    for (int c = 0; c < 8; ++c) {
                        size_t gi = i + (size_t)(c & 1), gj = j + (size_t)((c >> 1) & 1), gk = k + (size_t)((c >> 2) & 1);
                        size_t g = GRID(gi, gj, gk);
                        if (t.grid_part[g] == SOFT_PART_UNSET)
                            t.grid_part[g] = nearest_part(s, ak_vec3_make(org[0] + (float)gi * h, org[1] + (float)gj * h, org[2] + (float)gk * h));
                        parts[c] = t.grid_part[g];
                    }
                    bool together = true;
                    for (int a = 0; a < 8 && together; ++a)
                        for (int b = a + 1; b < 8 && together; ++b) together = parts_adjacent(&t, adj_words, parts[a], parts[b]);
                    if (!together) {
                        t.keep[cell] = 0;
                        s->cut_cells++;
                    }
                }
    }

    /* 2. nodes: the corners of kept cells, numbered in grid order */
    SOFT_ALLOC(t.grid_node, uint32_t, gnodes);
    size_t kept = 0;
    for (size_t c = 0; c < cells; ++c) kept += t.keep[c];
    if (kept == 0) {
        r = AK_ERR_EMPTY;
        goto fail;
    }
    for (size_t g = 0; g < gnodes; ++g) t.grid_node[g] = 0;
    for (size_t k = 0; k < nz; ++k)
        for (size_t j = 0; j < ny; ++j)
            for (size_t i = 0; i < nx; ++i)
                if (t.keep[(k * ny + j) * nx + i])
                    for (int c = 0; c < 8; ++c) t.grid_node[GRID(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))] = 1;
    size_t nn = 0;
    for (size_t g = 0; g < gnodes; ++g) t.grid_node[g] = t.grid_node[g] ? (uint32_t)nn++ : UINT32_MAX;
    s->node_count = nn;
    SOFT_ALLOC(s->rest, ak_vec3, nn);
    if (t.grid_part) {
        SOFT_ALLOC(t.node_part, uint32_t, nn);
        for (size_t g = 0; g < gnodes; ++g)
            if (t.grid_node[g] != UINT32_MAX) t.node_part[t.grid_node[g]] = t.grid_part[g];
    }
    for (size_t k = 0; k <= nz; ++k)
        for (size_t j = 0; j <= ny; ++j)
            for (size_t i = 0; i <= nx; ++i) {
                uint32_t id = t.grid_node[GRID(i, j, k)];
                if (id != UINT32_MAX)
                    s->rest[id] = ak_vec3_make(org[0] + (float)i * h, org[1] + (float)j * h, org[2] + (float)k * h);
            }

    /* 3. tets: 6 per kept cell, positively oriented */
    const size_t nt = kept * 6;
    s->tet_count = nt;
    SOFT_ALLOC(t.tets, uint32_t, 4 * nt);
    SOFT_ALLOC(t.cell_tet, uint32_t, cells);
    {
        size_t ti = 0;
        for (size_t k = 0; k < nz; ++k)
            for (size_t j = 0; j < ny; ++j)
                for (size_t i = 0; i < nx; ++i) {
                    size_t cell = (k * ny + j) * nx + i;
                    t.cell_tet[cell] = UINT32_MAX;
                    if (!t.keep[cell]) continue;
                    t.cell_tet[cell] = (uint32_t)ti;
                    for (int q = 0; q < 6; ++q, ++ti) {
                        uint32_t* tt = &t.tets[4 * ti];
                        for (int c = 0; c < 4; ++c) {
                            int corner = kuhn[q][c];
                            tt[c] = t.grid_node[GRID(i + (corner & 1), j + ((corner >> 1) & 1), k + ((corner >> 2) & 1))];
                        }
                        ak_vec3 e1 = ak_vec3_sub(s->rest[tt[1]], s->rest[tt[0]]);
                        ak_vec3 e2 = ak_vec3_sub(s->rest[tt[2]], s->rest[tt[0]]);
                        ak_vec3 e3v = ak_vec3_sub(s->rest[tt[3]], s->rest[tt[0]]);
                        if (ak_vec3_dot(e1, ak_vec3_cross(e2, e3v)) < 0.0f) {
                            uint32_t tmp = tt[2];
                            tt[2] = tt[3];
                            tt[3] = tmp;
                        }
                    }
                }
    }
#undef GRID

    /* 4. colour the tets greedily (no two of a colour share a node), then sort by colour */
    SOFT_ALLOC(t.color, uint32_t, nt);
    SOFT_ALLOC(t.used, uint64_t, 2 * nn);
    uint32_t ncol = 0;
    for (size_t q = 0; q < nt; ++q) {
        uint64_t m0 = 0, m1 = 0;
        for (int c = 0; c < 4; ++c) {
            m0 |= t.used[2 * t.tets[4 * q + c]];
            m1 |= t.used[2 * t.tets[4 * q + c] + 1];
        }
        uint32_t col = UINT32_MAX;
        for (uint32_t b = 0; b < SOFT_MAX_COLORS && col == UINT32_MAX; ++b)
            if (!((b < 64 ? m0 >> b : m1 >> (b - 64)) & 1u)) col = b;
        if (col == UINT32_MAX) {
            r = AK_ERR_UNSUPPORTED;
            goto fail;
        }
        t.color[q] = col;
        if (col + 1 > ncol) ncol = col + 1;
        for (int c = 0; c < 4; ++c) t.used[2 * t.tets[4 * q + c] + (col >= 64)] |= (uint64_t)1 << (col & 63);
    }
    s->color_count = ncol;
    SOFT_ALLOC(s->color_start, uint32_t, ncol + 1);
    SOFT_ALLOC(t.perm, uint32_t, nt);
    for (size_t q = 0; q < nt; ++q) s->color_start[t.color[q] + 1]++;
    for (uint32_t c = 0; c < ncol; ++c) s->color_start[c + 1] += s->color_start[c];
    {
        /* the colour masks are no longer needed: reuse them as the per-colour fill counters
         * (4 * nn uint32_t slots; a tet has 4 nodes, so ncol <= 128 <= 4 * nn for nn >= 32) */
        uint32_t* next = (uint32_t*)(void*)t.used;
        if (4 * nn < ncol) {
            r = AK_ERR_UNSUPPORTED;
            goto fail;
        }
        for (uint32_t c = 0; c < ncol; ++c) next[c] = s->color_start[c];
        for (size_t q = 0; q < nt; ++q) t.perm[q] = next[t.color[q]]++;
    }
    SOFT_ALLOC(s->tets, uint32_t, 4 * nt);
    for (size_t q = 0; q < nt; ++q) memcpy(&s->tets[4 * (size_t)t.perm[q]], &t.tets[4 * q], 4 * sizeof(uint32_t));

    /* 5. rest shapes and lumped masses */
    SOFT_ALLOC(s->dm_inv, float, 9 * nt);
    SOFT_ALLOC(s->volume, float, nt);
    SOFT_ALLOC(s->mass, float, nn);
    SOFT_ALLOC(s->inv_mass, float, nn);
    for (size_t q = 0; q < nt; ++q) {
        const uint32_t* tt = &s->tets[4 * q];
        ak_vec3 x0 = s->rest[tt[0]];
        ak_vec3 e[3] = {ak_vec3_sub(s->rest[tt[1]], x0), ak_vec3_sub(s->rest[tt[2]], x0), ak_vec3_sub(s->rest[tt[3]], x0)};
        float dm[9] = {e[0].x, e[0].y, e[0].z, e[1].x, e[1].y, e[1].z, e[2].x, e[2].y, e[2].z}, det;
        if (!mat3_inverse(dm, &s->dm_inv[9 * q], &det)) {
            r = AK_ERR_BAD_DATA;
            goto fail;
        }
        s->volume[q] = det / 6.0f;
        for (int c = 0; c < 4; ++c) s->mass[tt[c]] += d.density * s->volume[q] * 0.25f;
    }

    SOFT_ALLOC(s->dm_soa, float, 9 * nt);
    SOFT_ALLOC(s->tets_soa, uint32_t, 4 * nt);
    for (size_t q = 0; q < nt; ++q) {
        for (int i = 0; i < 9; ++i) s->dm_soa[(size_t)i * nt + q] = s->dm_inv[9 * q + (size_t)i];
        for (int k = 0; k < 4; ++k) s->tets_soa[(size_t)k * nt + q] = s->tets[4 * q + (size_t)k];
    }

    /* 6. embedding of the surface vertices */
    SOFT_ALLOC(s->embed_tet, uint32_t, nv);
    SOFT_ALLOC(s->embed_bary, float, 4 * nv);
    for (size_t v = 0; v < nv; ++v) {
        size_t ci[3];
        float p3[3] = {P[v].x, P[v].y, P[v].z};
        for (int a = 0; a < 3; ++a) {
            float f = floorf((p3[a] - org[a]) / h);
            ci[a] = f < 0.0f ? 0 : (size_t)f >= dim[a] ? dim[a] - 1 : (size_t)f;
        }
        /* the tet of the vertex's cell that holds it best; when that cell was dropped, or
         * holds nodes of a part that shares no joint with the vertex's bone, the best-fitting
         * tet of the nearest kept cells of its own parts (extrapolated barycentrics: exact at
         * the bind pose) */
        const uint32_t ov = t.owner[v];
        float best = -INFINITY, bary[4];
        uint32_t best_t = UINT32_MAX;
        for (long reach = 0; reach <= 2 && best_t == UINT32_MAX; ++reach)
            for (long dk = -reach; dk <= reach; ++dk)
                for (long dj = -reach; dj <= reach; ++dj)
                    for (long di = -reach; di <= reach; ++di) {
                        long mx = labs(di) > labs(dj) ? labs(di) : labs(dj);
                        if ((labs(dk) > mx ? labs(dk) : mx) != reach) continue; /* the shell only */
                        long ii = (long)ci[0] + di, jj = (long)ci[1] + dj, kk = (long)ci[2] + dk;
                        if (ii < 0 || jj < 0 || kk < 0 || ii >= (long)nx || jj >= (long)ny || kk >= (long)nz) continue;
                        uint32_t first = t.cell_tet[((size_t)kk * ny + (size_t)jj) * nx + (size_t)ii];
                        if (first == UINT32_MAX) continue;
                        for (uint32_t q = first; q < first + 6; ++q) {
                            uint32_t tq = t.perm[q];
                            if (!tet_fits(&t, adj_words, &s->tets[4 * tq], ov)) continue;
                            tet_bary(s->rest[s->tets[4 * tq]], &s->dm_inv[9 * tq], P[v], bary);
                            if (min4(bary) > best) {
                                best = min4(bary);
                                best_t = tq;
                            }
                        }
                    }
        for (int any = 0; any < 2 && best_t == UINT32_MAX; ++any) { /* nearest tet by centroid */
            float bd = INFINITY;
            for (size_t q = 0; q < nt; ++q) {
                const uint32_t* tt = &s->tets[4 * q];
                if (!any && !tet_fits(&t, adj_words, tt, ov)) continue;
                ak_vec3 cen = ak_vec3_scale(
                    ak_vec3_add(ak_vec3_add(s->rest[tt[0]], s->rest[tt[1]]), ak_vec3_add(s->rest[tt[2]], s->rest[tt[3]])), 0.25f);
                float dd = ak_vec3_length_sq(ak_vec3_sub(cen, P[v]));
                if (dd < bd) {
                    bd = dd;
                    best_t = (uint32_t)q;
                }
            }
        }
        s->embed_tet[v] = best_t;
        tet_bary(s->rest[s->tets[4 * best_t]], &s->dm_inv[9 * best_t], P[v], &s->embed_bary[4 * v]);
    }

    /* 8. node weights (inverse distance to the bones) and kinematic nodes */
    SOFT_ALLOC(s->node_joints, uint16_t, SOFT_INFLUENCES * nn);
    SOFT_ALLOC(s->node_weights, float, SOFT_INFLUENCES * nn);
    {
        /* only the bones that own surface vertices: a bone that moves no vertex (a leaf's
         * point bone) must not pull the flesh around it */
        ak_skin_bone* owning = (ak_skin_bone*)akp_alloc(A, nb * sizeof(ak_skin_bone));
        if (!owning) {
            r = AK_ERR_NO_MEMORY;
            goto fail;
        }
        size_t no = 0;
        for (size_t b = 0; b < nb; ++b)
            if (s->contact_radius[b] > 0.0f) owning[no++] = s->bones[b];
        if (no == 0) {
            memcpy(owning, s->bones, nb * sizeof(ak_skin_bone));
            no = nb;
        }
        ak_weights_desc wd = {.method = AK_WEIGHTS_DISTANCE,
                              .positions = {s->rest, nn},
                              .bones = {owning, no},
                              .max_influences = SOFT_INFLUENCES};
        r = ak_skin_weights_compute(&wd, alloc, (ak_u16_span){s->node_joints, SOFT_INFLUENCES * nn},
                                    (ak_f32_span){s->node_weights, SOFT_INFLUENCES * nn});
        akp_free(A, owning);
        if (r != AK_OK) goto fail;
    }
    SOFT_ALLOC(s->kinematic, uint8_t, nn);
    /* at least 1.2 cubes: every bone holds a column of nodes and its nearest neighbours */
    for (size_t b = 0; b < nb; ++b)
        s->core_radius[b] = s->contact_radius[b] > 0.0f ? ak_maxf(d.bone_radius * s->contact_radius[b], 1.2f * h) : 0.0f;
    /* the collider is the bone's core without the 1.2-cube floor: the floor makes every bone
     * hold lattice nodes, but as a collider it pushes the flesh next to a thin limb (CesiumMan's
     * waist beside the swinging thigh) away by up to a cube */
    for (size_t b = 0; b < nb; ++b) s->collide_radius[b] = d.bone_radius * s->contact_radius[b];
    /* kinematic: inside a capsule and bound (almost) rigidly to one joint, so that the nodes
     * around a joint, whose weights blend, are flesh */
    /* ... and not within three capsule radii (at most half its own bone's length) of
     * another bone: the flesh around a joint stays free, so that the bones' cores do not crush
     * it at a deep bend */
    const float zone = d.joint_zone;
    /* the default (joint_zone 0): where a bone's capsule is sized by its flesh (half its flesh
     * radius is more than the 1.2-cube floor: the lattice resolves the limb, as on the fat
     * builtin cylinder), the free zone around it also reaches two of its flesh radii (at most
     * half the node's own bone): the flesh that folds into a deep bend reaches that far. A thin limb
     * (CesiumMan's, one or two cubes across) keeps 1.5 capsule radii (docs/softskin.md) */
    const bool flesh_zone = !(desc_in && desc_in->joint_zone != 0.0f);
    /* per joint: whether any node became kinematic with these rules; a joint that got none (its
     * bones too short or too crowded for them: a dense skeleton at a coarse lattice) takes every
     * node inside its capsule that it weighs most */
    uint8_t* joint_has = (uint8_t*)akp_calloc(A, (size_t)s->max_joint + 1);
    if (!joint_has) {
        r = AK_ERR_NO_MEMORY;
        goto fail;
    }
    for (int pass = 0; pass < 2; ++pass)
        for (size_t n = 0; n < nn; ++n) {
            uint16_t part = s->node_joints[SOFT_INFLUENCES * n];
            if (pass == 0 ? s->node_weights[SOFT_INFLUENCES * n] < 0.99f : joint_has[part] != 0) continue;
            bool inside = false, near_other = false;
            float own_len = 0.0f;
            for (size_t b = 0; b < nb; ++b)
                if (s->bones[b].joint_index == part && s->core_radius[b] > 0.0f)
                    own_len = ak_maxf(own_len, ak_vec3_distance(s->bones[b].head, s->bones[b].tail));
            for (size_t b = 0; b < nb; ++b) {
                float core = s->core_radius[b];
                if (!(core > 0.0f)) continue;
                float d2 = akp_segment_dist_sq(s->rest[n], s->bones[b].head, s->bones[b].tail, NULL);
                float z = ak_minf(zone * core, own_len / 2.0f);
                if (flesh_zone && d.bone_radius * s->contact_radius[b] > 1.2f * h)
                    z = ak_minf(ak_maxf(zone * core, 2.0f * s->contact_radius[b]), own_len / 2.0f);
                if (s->bones[b].joint_index == part) inside = inside || d2 < core * core;
                else near_other = near_other || (pass == 0 && d2 < z * z);
            }
            s->kinematic[n] = inside && !near_other;
            if (pass == 0 && s->kinematic[n]) joint_has[part] = 1;
        }
    akp_free(A, joint_has);
    /* connected pieces without a kinematic node become kinematic whole */
    SOFT_ALLOC(t.uf, uint32_t, nn);
    SOFT_ALLOC(t.comp_kin, uint8_t, nn);
    for (size_t n = 0; n < nn; ++n) t.uf[n] = (uint32_t)n;
    for (size_t q = 0; q < nt; ++q)
        for (int c = 1; c < 4; ++c) {
            uint32_t a = uf_find(t.uf, s->tets[4 * q]), b = uf_find(t.uf, s->tets[4 * q + c]);
            if (a != b) t.uf[a < b ? b : a] = a < b ? a : b;
        }
    for (size_t n = 0; n < nn; ++n)
        if (s->kinematic[n]) t.comp_kin[uf_find(t.uf, (uint32_t)n)] = 1;
    for (size_t n = 0; n < nn; ++n) {
        if (!t.comp_kin[uf_find(t.uf, (uint32_t)n)]) s->kinematic[n] = 1;
        s->kin_count += s->kinematic[n];
        s->inv_mass[n] = s->kinematic[n] || !(s->mass[n] > 0.0f) ? 0.0f : 1.0f / s->mass[n];
    }

    /* 9. which bones each flesh node collides with */
    s->collide_words = (nb + 63) / 64;
    SOFT_ALLOC(s->collide, uint64_t, nn * s->collide_words);
    for (size_t n = 0; n < nn; ++n) {
        if (s->kinematic[n]) continue;
        uint16_t part = s->node_joints[n * SOFT_INFLUENCES];
        for (size_t b = 0; b < nb; ++b) {
            float rc = s->collide_radius[b];
            if (!(rc > 0.0f) || s->bones[b].joint_index == part) continue;
            if (akp_segment_dist_sq(s->rest[n], s->bones[b].head, s->bones[b].tail, NULL) < rc * rc) continue;
            s->collide[n * s->collide_words + b / 64] |= (uint64_t)1 << (b % 64);
        }
    }
    /* 10. joint contact planes: where bone c starts at bone p's end, the flesh of each side
     * stays on its side of the plane bisecting the two bones (a bent knee or elbow presses its
     * two sides flat against each other instead of passing through) */
    {
        size_t np = 0;
        for (int pass = 0; pass < 2; ++pass) {
            np = 0;
            for (size_t b1 = 0; b1 < nb; ++b1)
                for (size_t b2 = 0; b2 < nb; ++b2) {
                    const ak_skin_bone *P1 = &s->bones[b1], *C1 = &s->bones[b2];
                    if (b1 == b2 || !(s->contact_radius[b1] > 0.0f) || !(s->contact_radius[b2] > 0.0f)) continue;
                    if (P1->joint_index == C1->joint_index) continue;
                    if (ak_vec3_distance(P1->tail, C1->head) > 1e-4f * longest) continue;
                    if (ak_vec3_length(ak_vec3_sub(P1->tail, P1->head)) <= 0.0f || ak_vec3_length(ak_vec3_sub(C1->tail, C1->head)) <= 0.0f) continue;
                    if (pass == 1) {
                        s->planes[2 * np] = (uint32_t)b1;
                        s->planes[2 * np + 1] = (uint32_t)b2;
                    }
                    ++np;
                }
            if (pass == 0) {
                s->plane_count = (uint32_t)np;
                if (np == 0) break;
                SOFT_ALLOC(s->planes, uint32_t, 2 * np);
            }
        }
        SOFT_ALLOC(s->node_planes, int32_t, SOFT_NODE_PLANES * nn);
        for (size_t n = 0; n < nn && np; ++n) {
            if (s->kinematic[n]) continue;
            uint16_t part = s->node_joints[SOFT_INFLUENCES * n];
            uint32_t k = 0;
            for (uint32_t pl = 0; pl < s->plane_count && k < SOFT_NODE_PLANES; ++pl) {
                const ak_skin_bone *P1 = &s->bones[s->planes[2 * pl]], *C1 = &s->bones[s->planes[2 * pl + 1]];
                ak_vec3 u = ak_vec3_add(ak_vec3_normalize(ak_vec3_sub(P1->tail, P1->head)), ak_vec3_normalize(ak_vec3_sub(C1->tail, C1->head)));
                if (ak_vec3_length(u) < 0.1f) continue;
                ak_vec3 nrm = ak_vec3_normalize(u);
                /* the two limbs: as far as the longer bone plus its flesh */
                float reach = ak_maxf(ak_vec3_distance(P1->head, P1->tail), ak_vec3_distance(C1->head, C1->tail)) +
                              2.0f * ak_maxf(s->contact_radius[s->planes[2 * pl]], s->contact_radius[s->planes[2 * pl + 1]]);
                ak_vec3 rel = ak_vec3_sub(s->rest[n], P1->tail);
                if (ak_vec3_length(rel) > reach) continue;
                float sd = ak_vec3_dot(rel, nrm);
                if (sd < -0.5f * h && part == P1->joint_index) s->node_planes[SOFT_NODE_PLANES * n + k++] = (int32_t)pl + 1;
                else if (sd > 0.5f * h && part == C1->joint_index) s->node_planes[SOFT_NODE_PLANES * n + k++] = -((int32_t)pl + 1);
            }
        }
    }
    /* 11. contact beyond a joint's two bones (release_nodes): per joint plane, the nodes of its
     * parent side (the upper bone's joint and the joint above it: thigh and hips, upper arm and
     * chest) and of its child side (the lower bone's joint and every joint below it: shin, foot
     * and toes); and those of the parts beyond the two bones, each on its side of the bind
     * pose's plane by half a cube, that may take the plane at a deep bend */
    {
        const uint32_t np = s->plane_count;
        SOFT_ALLOC(s->plane_bent0, uint8_t, np + 1);
        SOFT_ALLOC(s->plane_bisector, ak_vec3, np + 1);
        SOFT_ALLOC(s->xnode_start, uint32_t, np + 1);
        SOFT_ALLOC(s->snode_start, uint32_t, 2 * np + 1);
        const size_t jw = ((size_t)s->max_joint + 64) / 64;
        /* [2 * jw] the parent side's joints, the child side's joints; then [nb] each bone's
         * bone above (one whose tail is its head, of another joint; UINT32_MAX: none) */
        uint64_t* jset = NULL;
        SOFT_ALLOC(jset, uint64_t, 2 * jw + (nb + 1) / 2);
        uint32_t* above = (uint32_t*)(void*)(jset + 2 * jw);
        for (size_t b = 0; b < nb; ++b) {
            above[b] = UINT32_MAX;
            for (size_t b2 = 0; b2 < nb && above[b] == UINT32_MAX; ++b2)
                if (s->bones[b2].joint_index != s->bones[b].joint_index &&
                    ak_vec3_distance(s->bones[b2].tail, s->bones[b].head) <= 1e-4f * longest)
                    above[b] = (uint32_t)b2;
        }
#define SOFT_JSET(set, j) (((set)[(j) / 64] >> ((j) % 64)) & 1u)
#define SOFT_JADD(set, j) ((set)[(j) / 64] |= (uint64_t)1 << ((j) % 64))
        size_t nx = 0, ns = 0;
        for (int pass = 0; pass < 2; ++pass) {
            nx = ns = 0;
            for (uint32_t pl = 0; pl < np; ++pl) {
                const ak_skin_bone *P1 = &s->bones[s->planes[2 * pl]], *C1 = &s->bones[s->planes[2 * pl + 1]];
                s->xnode_start[pl] = (uint32_t)nx;
                s->snode_start[2 * pl] = s->snode_start[2 * pl + 1] = (uint32_t)ns;
                ak_vec3 dp = ak_vec3_normalize(ak_vec3_sub(P1->tail, P1->head)), dc = ak_vec3_normalize(ak_vec3_sub(C1->tail, C1->head));
                s->plane_bent0[pl] = ak_vec3_dot(dp, dc) <= SOFT_RELEASE_BEND_COS;
                ak_vec3 u = ak_vec3_add(dp, dc);
                s->plane_bisector[pl] = ak_vec3_length(u) > 0.05f ? ak_vec3_normalize(u) : ak_vec3_zero();
                if (s->plane_bent0[pl] || ak_vec3_length(u) < 0.1f) continue;
                const ak_vec3 nrm = ak_vec3_normalize(u);
                memset(jset, 0, 2 * jw * sizeof(uint64_t));
                uint64_t *jp = jset, *jc = jset + jw;
                for (size_t b = 0; b < nb; ++b) { /* the lower bone's joint and every joint below it */
                    uint32_t k = (uint32_t)b;
                    for (size_t steps = 0; k != UINT32_MAX && steps <= nb; ++steps, k = above[k]) {
                        if (s->bones[k].joint_index == P1->joint_index) break;
                        if (s->bones[k].joint_index == C1->joint_index) {
                            SOFT_JADD(jc, s->bones[b].joint_index);
                            break;
                        }
                    }
                }
                SOFT_JADD(jp, P1->joint_index);
                for (size_t b = 0; b < nb; ++b) /* the joint above the upper bone */
                    if (ak_vec3_distance(s->bones[b].tail, P1->head) <= 1e-4f * longest && !SOFT_JSET(jc, s->bones[b].joint_index))
                        SOFT_JADD(jp, s->bones[b].joint_index);
                for (size_t n = 0; n < nn; ++n) {
                    uint16_t j = s->node_joints[SOFT_INFLUENCES * n];
                    if (!SOFT_JSET(jp, j)) continue;
                    if (pass == 1) s->snode[ns] = (uint32_t)n;
                    ++ns;
                }
                s->snode_start[2 * pl + 1] = (uint32_t)ns;
                for (size_t n = 0; n < nn; ++n) {
                    uint16_t j = s->node_joints[SOFT_INFLUENCES * n];
                    if (!SOFT_JSET(jc, j) || j == C1->joint_index) continue;
                    if (pass == 1) s->snode[ns] = (uint32_t)n;
                    ++ns;
                }
                for (size_t n = 0; n < nn; ++n) {
                    uint16_t j = s->node_joints[SOFT_INFLUENCES * n];
                    int32_t e = SOFT_JSET(jc, j) ? -((int32_t)n + 1) : SOFT_JSET(jp, j) ? (int32_t)n + 1 : 0;
                    if (!e || j == P1->joint_index || j == C1->joint_index) continue;
                    float sd = ak_vec3_dot(ak_vec3_sub(s->rest[n], P1->tail), nrm);
                    if (e > 0 ? sd < -0.5f * h : sd > 0.5f * h) {
                        if (pass == 1) s->xnode[nx] = e;
                        ++nx;
                    }
                }
            }
            s->xnode_start[np] = (uint32_t)nx;
            s->snode_start[2 * np] = (uint32_t)ns;
            if (pass == 0) {
                s->xnode = (int32_t*)akp_calloc(A, (nx ? nx : 1) * sizeof(int32_t));
                s->snode = (uint32_t*)akp_calloc(A, (ns ? ns : 1) * sizeof(uint32_t));
                if (!s->xnode || !s->snode) {
                    akp_free(A, jset);
                    r = AK_ERR_NO_MEMORY;
                    goto fail;
                }
            }
        }
#undef SOFT_JSET
#undef SOFT_JADD
        akp_free(A, jset);
    }
#undef SOFT_ALLOC
    tmp_free(A, &t);
    *out_soft = s;
    return AK_OK;
fail:
    tmp_free(A, &t);
    ak_skin_soft_destroy(s);
    return r;
}

/* ---- queries -------------------------------------------------------------------------- */

size_t ak_skin_soft_node_count(const ak_skin_soft* s) { return s ? s->node_count : 0; }
size_t ak_skin_soft_tet_count(const ak_skin_soft* s) { return s ? s->tet_count : 0; }
size_t ak_skin_soft_kinematic_count(const ak_skin_soft* s) { return s ? s->kin_count : 0; }
size_t ak_skin_soft_vertex_count(const ak_skin_soft* s) { return s ? s->vertex_count : 0; }
size_t ak_skin_soft_cut_cell_count(const ak_skin_soft* s) { return s ? s->cut_cells : 0; }

ak_result ak_skin_soft_rest_nodes(const ak_skin_soft* s, ak_vec3_span out) {
    if (!s || !out.ptr) return AK_ERR_NULL_ARG;
    if (out.count < s->node_count) return AK_ERR_SPAN_SMALL;
    memcpy(out.ptr, s->rest, s->node_count * sizeof(ak_vec3));
    return AK_OK;
}

ak_result ak_skin_soft_kinematic_flags(const ak_skin_soft* s, ak_u8_span out) {
    if (!s || !out.ptr) return AK_ERR_NULL_ARG;
    if (out.count < s->node_count) return AK_ERR_SPAN_SMALL;
    memcpy(out.ptr, s->kinematic, s->node_count);
    return AK_OK;
}

ak_result ak_skin_soft_tets(const ak_skin_soft* s, ak_u32_span out) {
    if (!s || !out.ptr) return AK_ERR_NULL_ARG;
    if (out.count < 4 * s->tet_count) return AK_ERR_SPAN_SMALL;
    memcpy(out.ptr, s->tets, 4 * s->tet_count * sizeof(uint32_t));
    return AK_OK;
}

static bool palette_finite(ak_mat4_cspan p) {
    for (size_t j = 0; j < p.count; ++j)
        for (int i = 0; i < 16; ++i)
            if (!isfinite(p.ptr[j].m[i])) return false;
    return true;
}

ak_result ak_skin_soft_state_init(const ak_skin_soft* s, ak_mat4_cspan palette, ak_vec3_span x, ak_vec3_span v) {
    if (!s || !palette.ptr || !x.ptr || !v.ptr) return AK_ERR_NULL_ARG;
    if (x.count < s->node_count || v.count < s->node_count || palette.count <= s->max_joint) return AK_ERR_SPAN_SMALL;
    if (!palette_finite(palette)) return AK_ERR_BAD_DATA;
    for (size_t n = 0; n < s->node_count; ++n) {
        x.ptr[n] = lbs_node(s, n, palette.ptr, palette.count);
        v.ptr[n] = ak_vec3_zero();
    }
    return AK_OK;
}

static void surface_range(const ak_skin_soft* s, const ak_vec3* x, ak_vec3* out, size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
        const uint32_t* tt = &s->tets[4 * (size_t)s->embed_tet[v]];
        const float* b = &s->embed_bary[4 * v];
        ak_vec3 p = ak_vec3_scale(x[tt[0]], b[0]);
        p = ak_vec3_madd(p, x[tt[1]], b[1]);
        p = ak_vec3_madd(p, x[tt[2]], b[2]);
        out[v] = ak_vec3_madd(p, x[tt[3]], b[3]);
    }
}

ak_result ak_skin_soft_surface(const ak_skin_soft* s, ak_vec3_cspan x, ak_vec3_span out) {
    if (!s || !x.ptr || !out.ptr) return AK_ERR_NULL_ARG;
    if (x.count < s->node_count || out.count < s->vertex_count) return AK_ERR_SPAN_SMALL;
    surface_range(s, x.ptr, out.ptr, 0, s->vertex_count);
    return AK_OK;
}

/* ---- step ----------------------------------------------------------------------------- */

/* A bone's collider at the step's pose: segment a + t ab, and a bounding sphere (centre mid,
 * squared radius reach2) that rejects the nodes far from it with one distance. */
/* A node's position with its inverse mass: 16 bytes, one 128-bit load in the SIMD solve. */
typedef struct soft_p4 {
    ak_vec3 p;
    float w;
} soft_p4;

typedef struct posed_bone {
    ak_vec3 a, ab, mid;
    float inv_len2, reach2, rc2;
} posed_bone;

/* Scratch layout: x[node], prev[node] (soft_p4), start[node], target[node], vref[node],
 * lambda_d[tet], lambda_h[tet], posed bones[bone] (this substep's), bone segments[4 * bone]
 * (head and tail at the step's start and end), joint planes[2 * plane] (the step's end),
 * start planes[2 * plane], substep planes[2 * plane], released[node], plane_active[plane]. */
size_t ak_skin_soft_step_scratch_size(const ak_skin_soft* s) {
    if (!s) return 0;
    return 64 + 2 * s->node_count * sizeof(soft_p4) + akp_align16(3 * s->node_count * sizeof(ak_vec3)) +
           akp_align16(2 * s->tet_count * sizeof(float)) + akp_align16(s->bone_count * sizeof(posed_bone)) +
           akp_align16(4 * s->bone_count * sizeof(ak_vec3)) + 3 * akp_align16(2 * s->plane_count * sizeof(ak_vec3)) +
           akp_align16(s->node_count * sizeof(int32_t)) + akp_align16(s->plane_count + 1) + akp_align16(s->node_count * sizeof(float));
}

ak_result ak_skin_soft_step_validate(const ak_skin_soft_step_job* j) {
    if (!j || !j->soft || !j->palette.ptr || !j->node_positions.ptr || !j->node_velocities.ptr || !j->scratch.ptr)
        return AK_ERR_NULL_ARG;
    const ak_skin_soft* s = j->soft;
    if (!(j->dt >= 0.0f && j->dt <= 1.0f) || j->thread_count > 64 || !ak_vec3_is_finite(j->gravity)) return AK_ERR_BAD_ARG;
    if (j->node_positions.count < s->node_count || j->node_velocities.count < s->node_count ||
        j->palette.count <= s->max_joint || j->scratch.count < ak_skin_soft_step_scratch_size(s) ||
        (j->previous_palette.ptr && j->previous_palette.count < j->palette.count) ||
        (j->out_positions.ptr && j->out_positions.count < s->vertex_count))
        return AK_ERR_SPAN_SMALL;
    if (!palette_finite(j->palette) || (j->previous_palette.ptr && !palette_finite(j->previous_palette))) return AK_ERR_BAD_DATA;
    return AK_OK;
}

typedef struct step_ctx {
    const ak_skin_soft* s;
    soft_p4 *x, *prev; /* positions (w: inverse mass) during the step, and at the substep's start */
    ak_vec3 *v, *start, *target, *planes, *vref;
    ak_vec3 *planes0, *psub; /* [2 * plane] the planes at the step's start, and this substep's */
    ak_vec3* seg;            /* [4 * bone] head, tail at the step's start; head, tail at its end */
    uint8_t* plane_active; /* [plane] bent past 90 deg now, not at the bind pose */
    int32_t* released; /* [node] kinematic node simulated this step, or flesh node held by a
                          plane beyond its bones (node_xplanes): +(p + 1) parent side of plane
                          p, -(p + 1) child side; 0 none */
    posed_bone* bones; /* this substep's (pose_substep) */
    float jiggle; /* 1 - exp(-jiggle_damping h) */
    float tether; /* (omega h)^2 / (1 + (omega h)^2): the XPBD step of a released node's tether */
    float* lambda;
    float h, gamma, adev, ahyd;
    float* hold; /* [node] a released kinematic node's tether step (release_nodes) */
    bool simd; /* the CPU runs solve_tets8 */
    uint32_t iterations; /* adev = 1 / (mu h^2), ahyd = 1 / (lambda h^2): divide by V */
    float hyd_rest;             /* 1 + mu / lambda */
    ak_vec3 gravity;
} step_ctx;

/* One tetrahedron's coupled deviatoric + hydrostatic XPBD solve. The AVX2 path below
 * (solve_tets8) performs the same float operations in the same order on 8 tets of a colour, so
 * both give the same bits (the build does not contract a * b + c). */
static void solve_tet(const step_ctx* c, size_t q) {
    const ak_skin_soft* s = c->s;
    const uint32_t* tt = &s->tets[4 * q];
    soft_p4* x = c->x;
    /* the step's inverse masses (x.w: a released kinematic node has its mass) */
    const float w[4] = {x[tt[0]].w, x[tt[1]].w, x[tt[2]].w, x[tt[3]].w};
    if (w[0] + w[1] + w[2] + w[3] == 0.0f) return;
    const float* m = &s->dm_inv[9 * q];
    const ak_vec3 x0 = x[tt[0]].p;
    const ak_vec3 d1 = ak_vec3_sub(x[tt[1]].p, x0), d2 = ak_vec3_sub(x[tt[2]].p, x0), d3 = ak_vec3_sub(x[tt[3]].p, x0);
    /* F = Ds Dm^-1: column j = d1 m[0 + 3j] + d2 m[1 + 3j] + d3 m[2 + 3j] */
    ak_vec3 f[3];
    for (int jc = 0; jc < 3; ++jc)
        f[jc] = ak_vec3_madd(ak_vec3_madd(ak_vec3_scale(d1, m[3 * jc]), d2, m[1 + 3 * jc]), d3, m[2 + 3 * jc]);
    const float cd = sqrtf(ak_vec3_length_sq(f[0]) + ak_vec3_length_sq(f[1]) + ak_vec3_length_sq(f[2]));
    const ak_vec3 ph[3] = {ak_vec3_cross(f[1], f[2]), ak_vec3_cross(f[2], f[0]), ak_vec3_cross(f[0], f[1])};
    const float ch = ak_vec3_dot(f[0], ph[0]) - c->hyd_rest;
    /* node gradients: g_k = sum_j P_col_j m[k + 3j] (k = 1..3), g_0 = -sum */
    ak_vec3 gd[4], gh[4];
    const bool collapsed = !(cd > 1e-12f);
    const float inv_cd = collapsed ? 0.0f : 1.0f / cd;
    for (int k = 0; k < 3; ++k) {
        gd[k + 1] = ak_vec3_madd(ak_vec3_madd(ak_vec3_scale(f[0], m[k] * inv_cd), f[1], m[k + 3] * inv_cd), f[2], m[k + 6] * inv_cd);
        gh[k + 1] = ak_vec3_madd(ak_vec3_madd(ak_vec3_scale(ph[0], m[k]), ph[1], m[k + 3]), ph[2], m[k + 6]);
    }
    gd[0] = ak_vec3_neg(ak_vec3_add(ak_vec3_add(gd[1], gd[2]), gd[3]));
    gh[0] = ak_vec3_neg(ak_vec3_add(ak_vec3_add(gh[1], gh[2]), gh[3]));
    float a11 = w[0] * ak_vec3_dot(gd[0], gd[0]), a12 = w[0] * ak_vec3_dot(gd[0], gh[0]), a22 = w[0] * ak_vec3_dot(gh[0], gh[0]);
    for (int k = 1; k < 4; ++k) {
        a11 += w[k] * ak_vec3_dot(gd[k], gd[k]);
        a12 += w[k] * ak_vec3_dot(gd[k], gh[k]);
        a22 += w[k] * ak_vec3_dot(gh[k], gh[k]);
    }
    /* Rayleigh damping: the motion of this substep along each gradient */
    float vd = 0.0f;
    if (c->gamma > 0.0f) {
        vd = ak_vec3_dot(gd[0], ak_vec3_sub(x[tt[0]].p, c->prev[tt[0]].p));
        for (int k = 1; k < 4; ++k) vd += ak_vec3_dot(gd[k], ak_vec3_sub(x[tt[k]].p, c->prev[tt[k]].p));
    }
    const float vol = s->volume[q];
    const float atd = c->adev / vol, ath = c->ahyd / vol, g1 = 1.0f + c->gamma;
    float *lam_d = &c->lambda[q], *lam_h = &c->lambda[s->tet_count + q];
    const float b1 = -cd - atd * *lam_d - c->gamma * vd;
    /* damping on the deviatoric constraint only: damping the stiff volume term makes the
     * volume creep back over many steps. Row i is (1 + gamma_i) (grad C_i . dx) + alpha~_i
     * dlambda_i = b_i: each constraint damps the motion along its own gradient, so the rest
     * state (where the two gradients are parallel and the corrections cancel) stays a fixed
     * point for any damping */
    const float b2 = -ch - ath * *lam_h;
    const float m11 = g1 * a11 + atd, m12 = g1 * a12, m22 = a22 + ath;
    float dl1, dl2;
    if (collapsed) { /* collapsed to a point: hydrostatic alone */
        dl1 = 0.0f;
        dl2 = m22 > 0.0f ? b2 / m22 : 0.0f;
    } else {
        const float dt2 = m11 * m22 - m12 * a12;
        if (!(fabsf(dt2) > 1e-30f)) return;
        dl1 = (b1 * m22 - b2 * m12) / dt2;
        dl2 = (m11 * b2 - a12 * b1) / dt2;
    }
    if (!(fabsf(dl1) < INFINITY) || !(fabsf(dl2) < INFINITY)) return;
    *lam_d += dl1;
    *lam_h += dl2;
    for (int k = 0; k < 4; ++k)
        if (w[k] > 0.0f)
            x[tt[k]].p = ak_vec3_add(x[tt[k]].p, ak_vec3_scale(ak_vec3_add(ak_vec3_scale(gd[k], dl1), ak_vec3_scale(gh[k], dl2)), w[k]));
}

#if SOFT_SIMD
typedef __m256 v8;
typedef struct v8x3 {
    v8 x, y, z;
} v8x3;
#define SOFT_AVX2 __attribute__((target("avx2"))) static inline
SOFT_AVX2 v8 v8_set(float f) { return _mm256_set1_ps(f); }
SOFT_AVX2 v8x3 v3_sub(v8x3 a, v8x3 b) { return (v8x3){_mm256_sub_ps(a.x, b.x), _mm256_sub_ps(a.y, b.y), _mm256_sub_ps(a.z, b.z)}; }
SOFT_AVX2 v8x3 v3_add(v8x3 a, v8x3 b) { return (v8x3){_mm256_add_ps(a.x, b.x), _mm256_add_ps(a.y, b.y), _mm256_add_ps(a.z, b.z)}; }
SOFT_AVX2 v8x3 v3_scale(v8x3 a, v8 s) { return (v8x3){_mm256_mul_ps(a.x, s), _mm256_mul_ps(a.y, s), _mm256_mul_ps(a.z, s)}; }
SOFT_AVX2 v8x3 v3_madd(v8x3 a, v8x3 b, v8 s) { return v3_add(a, v3_scale(b, s)); }
SOFT_AVX2 v8 v3_dot(v8x3 a, v8x3 b) {
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_mul_ps(a.y, b.y)), _mm256_mul_ps(a.z, b.z));
}
SOFT_AVX2 v8x3 v3_cross(v8x3 a, v8x3 b) {
    return (v8x3){_mm256_sub_ps(_mm256_mul_ps(a.y, b.z), _mm256_mul_ps(a.z, b.y)), _mm256_sub_ps(_mm256_mul_ps(a.z, b.x), _mm256_mul_ps(a.x, b.z)),
                  _mm256_sub_ps(_mm256_mul_ps(a.x, b.y), _mm256_mul_ps(a.y, b.x))};
}
SOFT_AVX2 v8x3 v3_neg(v8x3 a) {
    const v8 sg = _mm256_set1_ps(-0.0f);
    return (v8x3){_mm256_xor_ps(a.x, sg), _mm256_xor_ps(a.y, sg), _mm256_xor_ps(a.z, sg)};
}
/* Nodes idx[0..7] -> lanes: two 128-bit loads per register, then a 4x4 transpose per half. */
SOFT_AVX2 v8x3 p4_gather(const soft_p4* x, const uint32_t* idx, v8* w) {
    v8 r[4];
    for (int e = 0; e < 4; ++e)
        r[e] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&x[idx[e]].p.x)), _mm_loadu_ps(&x[idx[4 + e]].p.x), 1);
    const v8 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
    const v8 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    if (w) *w = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    return (v8x3){_mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
                  _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0))};
}

/* Lanes -> nodes idx[0..7] (x, y, z, w: one 128-bit store each). */
SOFT_AVX2 void p4_scatter(soft_p4* x, const uint32_t* idx, v8x3 p, v8 w) {
    const v8 t0 = _mm256_unpacklo_ps(p.x, p.y), t1 = _mm256_unpackhi_ps(p.x, p.y);
    const v8 t2 = _mm256_unpacklo_ps(p.z, w), t3 = _mm256_unpackhi_ps(p.z, w);
    v8 r[4];
    r[0] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    r[1] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    r[2] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    r[3] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    for (int e = 0; e < 4; ++e) {
        _mm_storeu_ps(&x[idx[e]].p.x, _mm256_castps256_ps128(r[e]));
        _mm_storeu_ps(&x[idx[4 + e]].p.x, _mm256_extractf128_ps(r[e], 1));
    }
}
SOFT_AVX2 v8 v8_finite(v8 a) { /* all ones where |a| < inf (not NaN) */
    return _mm256_cmp_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), a), _mm256_set1_ps(INFINITY), _CMP_LT_OQ);
}

/* solve_tet on the 8 tets q .. q + 7 of one colour (no two share a node). */
__attribute__((target("avx2"))) static void solve_tets8(const step_ctx* c, size_t q) {
    const ak_skin_soft* s = c->s;
    const size_t nt = s->tet_count;
    const uint32_t* id[4];
    v8 w[4];
    v8x3 p[4];
    for (int k = 0; k < 4; ++k) {
        id[k] = &s->tets_soa[(size_t)k * nt + q];
        p[k] = p4_gather(c->x, id[k], &w[k]);
    }
    const v8 zero = _mm256_setzero_ps(), one = v8_set(1.0f);
    const v8 active = _mm256_cmp_ps(_mm256_add_ps(_mm256_add_ps(_mm256_add_ps(w[0], w[1]), w[2]), w[3]), zero, _CMP_NEQ_UQ);
    if (_mm256_movemask_ps(active) == 0) return;
    v8 m[9];
    for (int i = 0; i < 9; ++i) m[i] = _mm256_loadu_ps(&s->dm_soa[(size_t)i * nt + q]);
    const v8x3 d1 = v3_sub(p[1], p[0]), d2 = v3_sub(p[2], p[0]), d3 = v3_sub(p[3], p[0]);
    v8x3 f[3];
    for (int jc = 0; jc < 3; ++jc) f[jc] = v3_madd(v3_madd(v3_scale(d1, m[3 * jc]), d2, m[1 + 3 * jc]), d3, m[2 + 3 * jc]);
    const v8 cd = _mm256_sqrt_ps(_mm256_add_ps(_mm256_add_ps(v3_dot(f[0], f[0]), v3_dot(f[1], f[1])), v3_dot(f[2], f[2])));
    const v8x3 ph[3] = {v3_cross(f[1], f[2]), v3_cross(f[2], f[0]), v3_cross(f[0], f[1])};
    const v8 ch = _mm256_sub_ps(v3_dot(f[0], ph[0]), v8_set(c->hyd_rest));
    const v8 ok_cd = _mm256_cmp_ps(cd, v8_set(1e-12f), _CMP_GT_OQ);
    const v8 inv_cd = _mm256_and_ps(ok_cd, _mm256_div_ps(one, cd));
    v8x3 gd[4], gh[4];
    for (int k = 0; k < 3; ++k) {
        gd[k + 1] = v3_madd(v3_madd(v3_scale(f[0], _mm256_mul_ps(m[k], inv_cd)), f[1], _mm256_mul_ps(m[k + 3], inv_cd)), f[2],
                            _mm256_mul_ps(m[k + 6], inv_cd));
        gh[k + 1] = v3_madd(v3_madd(v3_scale(ph[0], m[k]), ph[1], m[k + 3]), ph[2], m[k + 6]);
    }
    gd[0] = v3_neg(v3_add(v3_add(gd[1], gd[2]), gd[3]));
    gh[0] = v3_neg(v3_add(v3_add(gh[1], gh[2]), gh[3]));
    v8 a11 = _mm256_mul_ps(w[0], v3_dot(gd[0], gd[0])), a12 = _mm256_mul_ps(w[0], v3_dot(gd[0], gh[0])),
       a22 = _mm256_mul_ps(w[0], v3_dot(gh[0], gh[0]));
    for (int k = 1; k < 4; ++k) {
        a11 = _mm256_add_ps(a11, _mm256_mul_ps(w[k], v3_dot(gd[k], gd[k])));
        a12 = _mm256_add_ps(a12, _mm256_mul_ps(w[k], v3_dot(gd[k], gh[k])));
        a22 = _mm256_add_ps(a22, _mm256_mul_ps(w[k], v3_dot(gh[k], gh[k])));
    }
    v8 vd = zero;
    if (c->gamma > 0.0f) {
        vd = v3_dot(gd[0], v3_sub(p[0], p4_gather(c->prev, id[0], NULL)));
        for (int k = 1; k < 4; ++k) vd = _mm256_add_ps(vd, v3_dot(gd[k], v3_sub(p[k], p4_gather(c->prev, id[k], NULL))));
    }
    const v8 vol = _mm256_loadu_ps(&s->volume[q]);
    const v8 atd = _mm256_div_ps(v8_set(c->adev), vol), ath = _mm256_div_ps(v8_set(c->ahyd), vol), g1 = v8_set(1.0f + c->gamma);
    float *lam_d = &c->lambda[q], *lam_h = &c->lambda[s->tet_count + q];
    const v8 ld = _mm256_loadu_ps(lam_d), lh = _mm256_loadu_ps(lam_h);
    const v8 b1 = _mm256_sub_ps(_mm256_sub_ps(_mm256_xor_ps(cd, v8_set(-0.0f)), _mm256_mul_ps(atd, ld)), _mm256_mul_ps(v8_set(c->gamma), vd));
    const v8 b2 = _mm256_sub_ps(_mm256_xor_ps(ch, v8_set(-0.0f)), _mm256_mul_ps(ath, lh));
    const v8 m11 = _mm256_add_ps(_mm256_mul_ps(g1, a11), atd), m12 = _mm256_mul_ps(g1, a12), m22 = _mm256_add_ps(a22, ath);
    /* collapsed lanes: hydrostatic alone */
    const v8 dl2c = _mm256_and_ps(_mm256_cmp_ps(m22, zero, _CMP_GT_OQ), _mm256_div_ps(b2, m22));
    const v8 dt2 = _mm256_sub_ps(_mm256_mul_ps(m11, m22), _mm256_mul_ps(m12, a12));
    const v8 ok_dt = _mm256_cmp_ps(_mm256_andnot_ps(v8_set(-0.0f), dt2), v8_set(1e-30f), _CMP_GT_OQ);
    v8 dl1 = _mm256_div_ps(_mm256_sub_ps(_mm256_mul_ps(b1, m22), _mm256_mul_ps(b2, m12)), dt2);
    v8 dl2 = _mm256_div_ps(_mm256_sub_ps(_mm256_mul_ps(m11, b2), _mm256_mul_ps(a12, b1)), dt2);
    dl1 = _mm256_and_ps(ok_cd, dl1);
    dl2 = _mm256_blendv_ps(dl2c, dl2, ok_cd);
    const v8 valid = _mm256_and_ps(_mm256_and_ps(active, _mm256_or_ps(ok_dt, _mm256_xor_ps(ok_cd, _mm256_castsi256_ps(_mm256_set1_epi32(-1))))),
                                   _mm256_and_ps(v8_finite(dl1), v8_finite(dl2)));
    const int vmask = _mm256_movemask_ps(valid);
    if (vmask == 0) return;
    _mm256_storeu_ps(lam_d, _mm256_blendv_ps(ld, _mm256_add_ps(ld, dl1), valid));
    _mm256_storeu_ps(lam_h, _mm256_blendv_ps(lh, _mm256_add_ps(lh, dl2), valid));
    /* lanes not updated write their own values back: no other tet of the colour has their nodes */
    for (int k = 0; k < 4; ++k) {
        const v8 upd = _mm256_and_ps(valid, _mm256_cmp_ps(w[k], zero, _CMP_GT_OQ));
        const v8x3 np = v3_add(p[k], v3_scale(v3_add(v3_scale(gd[k], dl1), v3_scale(gh[k], dl2)), w[k]));
        const v8x3 out = {_mm256_blendv_ps(p[k].x, np.x, upd), _mm256_blendv_ps(p[k].y, np.y, upd), _mm256_blendv_ps(p[k].z, np.z, upd)};
        p4_scatter(c->x, id[k], out, w[k]);
    }
}
#endif

/* The tets [b, e) of one colour: 8 at a time where the CPU has AVX2, the rest one by one. */
static void solve_range(const step_ctx* c, size_t b, size_t e) {
    size_t q = b;
#if SOFT_SIMD
    if (c->simd)
        for (; q + 8 <= e; q += 8) solve_tets8(c, q);
#endif
    for (; q < e; ++q) solve_tet(c, q);
}

static void plane_clamp(const step_ctx* c, size_t n, int32_t e) {
    size_t pl = (size_t)(e > 0 ? e : -e) - 1;
    ak_vec3 nrm = c->psub[2 * pl + 1];
    if (nrm.x == 0.0f && nrm.y == 0.0f && nrm.z == 0.0f) return;
    float sd = ak_vec3_dot(ak_vec3_sub(c->x[n].p, c->psub[2 * pl]), nrm);
    if (e > 0 ? sd > 0.0f : sd < 0.0f) c->x[n].p = ak_vec3_madd(c->x[n].p, nrm, -sd);
}

static void collide_node(const step_ctx* c, size_t n) {
    const ak_skin_soft* s = c->s;
    if (s->kinematic[n]) { /* released for this step: its own plane only */
        plane_clamp(c, n, c->released[n]);
        return;
    }
    for (uint32_t k = 0; k < SOFT_NODE_PLANES && s->plane_count; ++k) {
        int32_t e = s->node_planes[SOFT_NODE_PLANES * n + k];
        if (e == 0) break;
        plane_clamp(c, n, e);
    }
    if (c->released[n]) plane_clamp(c, n, c->released[n]); /* a plane beyond its bones, this step */
    const uint64_t* bits = &s->collide[n * s->collide_words];
    for (size_t wi = 0; wi < s->collide_words; ++wi)
        for (uint64_t m = bits[wi]; m; m &= m - 1) {
            size_t b = wi * 64 + (size_t)__builtin_ctzll(m);
            const posed_bone* pb = &c->bones[b];
            ak_vec3 p = c->x[n].p;
            if (ak_vec3_length_sq(ak_vec3_sub(p, pb->mid)) >= pb->reach2) continue;
            ak_vec3 ap = ak_vec3_sub(p, pb->a);
            float tt = ak_clampf(ak_vec3_dot(ap, pb->ab) * pb->inv_len2, 0.0f, 1.0f);
            ak_vec3 cp = ak_vec3_madd(pb->a, pb->ab, tt);
            float d2 = ak_vec3_length_sq(ak_vec3_sub(p, cp));
            if (d2 >= pb->rc2 || d2 < 1e-20f) continue;
            c->x[n].p = ak_vec3_madd(cp, ak_vec3_sub(p, cp), sqrtf(pb->rc2 / d2));
        }
}

/* Threads: the phases run over node ranges or over the tets of one colour, with a barrier
 * between phases. With one thread the same loops run in the same order. Workers wait for a
 * start signal carrying the final thread count, so a thread that fails to start only lowers it. */
typedef struct soft_team {
    const step_ctx* c;
    pthread_mutex_t mutex;
    pthread_cond_t cond;
    pthread_barrier_t barrier;
    int go;      /* 1: run; -1: give up */
    uint32_t count;
} soft_team;

typedef struct soft_worker {
    soft_team* team;
    uint32_t index;
} soft_worker;

static void range_of(size_t n, uint32_t index, uint32_t count, size_t* b, size_t* e) {
    *b = n * index / count;
    *e = n * (index + 1) / count;
}

static void sync(soft_team* t) {
    if (t->count > 1) pthread_barrier_wait(&t->barrier);
}

/* The normal of a joint's contact plane under the palette matrices mp (parent bone) and mc
 * (child): the bind pose's bisecting plane of the two bones' directions, turned by the
 * rotation halfway between the two bones' rotations: the plane the two sides are symmetric
 * about. Where the child turns in the plane the two bones span (a hinge) it is the posed
 * bones' bisector, as before; it differs where the child's direction passes near the parent's
 * reversed, out of that plane: there the bisector of the posed directions (u = up + uc, the
 * sum of two nearly opposite unit vectors) swung 47 deg in the last step of CesiumMan's elbow
 * folding to 150 deg (13.6 in the step before, 3.75 while the bend was shallow), its far parts
 * sweeping the flesh at 10-19 m/s while no point of the bones moved faster than 3 m/s: 219 J
 * (docs/softskin.md). The halfway rotation turns at half the bones' relative rate. Bones that
 * meet nearly antiparallel at the bind pose (no bind bisector) keep u. u0 is the plane's bind
 * bisector (s->plane_bisector, computed once at create; zero for those bones). */
static ak_vec3 plane_normal(ak_vec3 u0, ak_mat4 mp, ak_mat4 mc, ak_vec3 u) {
    if (u0.x == 0.0f && u0.y == 0.0f && u0.z == 0.0f) return ak_vec3_normalize(u);
    ak_quat qp = ak_quat_from_mat3(ak_mat4_to_mat3(mp)), qc = ak_quat_from_mat3(ak_mat4_to_mat3(mc));
    if (ak_quat_dot(qp, qc) < 0.0f) qc = ak_quat_neg(qc);
    ak_quat mid = ak_quat_normalize(ak_quat_add(qp, qc));
    return ak_vec3_normalize(ak_quat_rotate(mid, u0));
}

/* The colliders at fraction `frac` of the step: the bone cores' segments and the joint planes
 * move from where the previous palette put them to where this step's puts them, as the
 * kinematic nodes do (linearly across the substeps). Posed at the step's end for every substep,
 * a turning plane jumped a step's worth into the flesh at the first substep and the projection
 * gave the nodes it moved that distance over one substep's time (1/2400 s): with the posed
 * bisector as the normal, the plane's projections put 2860 J into the last frame of CesiumMan's
 * elbow folding to 150 deg (219 J largest; 48 J interpolated); with plane_normal, the left knee
 * folding to 150 deg reaches 144 J unmoved, 52.8 J interpolated (docs/softskin.md). */
static void pose_substep(const step_ctx* c, float frac) {
    const ak_skin_soft* s = c->s;
    for (size_t b = 0; b < s->bone_count; ++b) {
        const ak_vec3* g = &c->seg[4 * b];
        ak_vec3 a = ak_vec3_lerp(g[0], g[2], frac), e = ak_vec3_lerp(g[1], g[3], frac);
        posed_bone* pb = &c->bones[b];
        pb->a = a;
        pb->ab = ak_vec3_sub(e, a);
        float len2 = ak_vec3_length_sq(pb->ab), rc = s->collide_radius[b];
        pb->inv_len2 = len2 > 0.0f ? 1.0f / len2 : 0.0f;
        pb->mid = ak_vec3_lerp(a, e, 0.5f);
        float reach = 0.5f * sqrtf(len2) + rc;
        pb->reach2 = 1.0001f * reach * reach + 1e-20f;
        pb->rc2 = rc * rc;
    }
    for (uint32_t pl = 0; pl < s->plane_count; ++pl) {
        ak_vec3 n0 = c->planes0[2 * pl + 1], n1 = c->planes[2 * pl + 1];
        c->psub[2 * pl] = ak_vec3_lerp(c->planes0[2 * pl], c->planes[2 * pl], frac);
        /* a plane off at either end (folded flat) takes the end's */
        bool off0 = n0.x == 0.0f && n0.y == 0.0f && n0.z == 0.0f, off1 = n1.x == 0.0f && n1.y == 0.0f && n1.z == 0.0f;
        c->psub[2 * pl + 1] = off0 || off1 ? n1 : ak_vec3_normalize(ak_vec3_lerp(n0, n1, frac));
    }
}

static void step_work(soft_team* team, uint32_t index) {
    const step_ctx* c = team->c;
    const ak_skin_soft* s = c->s;
    const uint32_t count = team->count;
    size_t nb, ne, tb, te;
    range_of(s->node_count, index, count, &nb, &ne);
    range_of(s->tet_count, index, count, &tb, &te);
    const uint32_t S = s->substeps;
    for (uint32_t sub = 0; sub < S; ++sub) {
        float frac = (float)(sub + 1) / (float)S;
        if (index == 0) pose_substep(c, frac); /* read after the barriers below */
        for (size_t n = nb; n < ne; ++n) {
            c->prev[n] = c->x[n];
            if (s->kinematic[n] && !c->released[n]) c->x[n].p = ak_vec3_lerp(c->start[n], c->target[n], frac);
            else {
                c->v[n] = ak_vec3_madd(c->v[n], c->gravity, c->h);
                c->x[n].p = ak_vec3_madd(c->x[n].p, c->v[n], c->h);
            }
        }
        for (size_t q = tb; q < te; ++q) c->lambda[q] = c->lambda[s->tet_count + q] = 0.0f;
        sync(team);
        for (uint32_t it = 0; it < c->iterations; ++it)
        for (uint32_t col = 0; col < s->color_count; ++col) {
            size_t cb = s->color_start[col], ce = s->color_start[col + 1], b, e;
            range_of(ce - cb, index, count, &b, &e);
            solve_range(c, cb + b, cb + e);
            sync(team);
        }
        float inv_h = 1.0f / c->h;
        const float back = c->h * (float)(S - sub - 1);
        for (size_t n = nb; n < ne; ++n) {
            const bool sim = !s->kinematic[n] || c->released[n];
            if (sim && s->kinematic[n] && c->hold[n] > 0.0f) {
                /* a released kinematic node: its tether to the skinned position at this substep */
                ak_vec3 t = ak_vec3_madd(c->target[n], c->vref[n], -back);
                c->x[n].p = ak_vec3_madd(c->x[n].p, ak_vec3_sub(t, c->x[n].p), c->hold[n]);
            }
            if (sim) collide_node(c, n);
            c->v[n] = ak_vec3_scale(ak_vec3_sub(c->x[n].p, c->prev[n].p), inv_h);
            /* jiggle damping: velocity relative to the skinned motion decays */
            if (sim) c->v[n] = ak_vec3_madd(c->v[n], ak_vec3_sub(c->v[n], c->vref[n]), -c->jiggle);
        }
        sync(team);
    }
}

static void* step_thread(void* arg) {
    soft_worker* w = (soft_worker*)arg;
    soft_team* t = w->team;
    pthread_mutex_lock(&t->mutex);
    while (t->go == 0) pthread_cond_wait(&t->cond, &t->mutex);
    int go = t->go;
    pthread_mutex_unlock(&t->mutex);
    if (go > 0 && w->index < t->count) step_work(t, w->index);
    return NULL;
}

/* The cone rule: a kinematic node of either bone of a joint bent past 90 deg whose target lies
 * near its own side of the joint's contact plane (closer to the plane than SOFT_RELEASE_CONE
 * times its distance from the joint, or already across it) is flesh for this step, held on its
 * side of the plane: at a deep bend the two bones' cores would otherwise crush the flesh
 * between them (docs/softskin.md). A node that lies within the cone of the bind pose's plane
 * (a hip or shoulder whose bones meet at a steep angle at rest) stays kinematic.
 * Parts beyond the two bones (issue 29: at a folded knee the heel and calf reached the thigh
 * and buttock, which no plane held): at a joint bent past 90 deg (and not at the bind pose), a
 * node of the part above the upper bone (the hips) whose skinned position lies within
 * SOFT_CONTACT_REACH cubes of a skinned node of the parts below the lower bone (foot, toes),
 * and a node of those parts that close to a node of the parent side (thigh, hips), is held on
 * its side of the plane for this step (create, step 11); a kinematic one only when its skinned
 * position is also within half a cube of the plane or across it, and it is then simulated like
 * a released node. The gate reads skinned positions: gated on where the flesh was, nodes
 * flickered in and out of contact from step to step and the held knee kept 4 J. The chest at
 * the elbow is not gated by the forearm, only by the parts below it (the hand, which has no
 * nodes of its own on CesiumMan): gated by the forearm, the chest's flesh pressed against the
 * plane where the forearm only passed beside it, and the held elbow at 130 deg kept 0.016 J
 * instead of 0.006. */
static void release_nodes(const ak_skin_soft* s, step_ctx* c, const ak_mat4* palette) {
    const size_t nn = s->node_count;
    memset(c->released, 0, nn * sizeof(int32_t));
    for (uint32_t pl = 0; pl < s->plane_count; ++pl) {
        ak_vec3 nrm = c->planes[2 * pl + 1], o = c->planes[2 * pl];
        if (nrm.x == 0.0f && nrm.y == 0.0f && nrm.z == 0.0f) continue;
        const uint32_t bp = s->planes[2 * pl], bc = s->planes[2 * pl + 1];
        const ak_skin_bone *P1 = &s->bones[bp], *C1 = &s->bones[bc];
        /* the plane at the bind pose: a node already within the cone there (the bones of a hip
         * or a shoulder meet at a steep angle at rest) stays kinematic */
        const ak_vec3 nrm0 = s->plane_bisector[pl];
        if (nrm0.x == 0.0f && nrm0.y == 0.0f && nrm0.z == 0.0f) continue;
        { /* bent past SOFT_RELEASE_BEND_COS (90 deg): a walk's knees and elbows stay as before */
            const ak_mat4 mp = palette[P1->joint_index], mc = palette[C1->joint_index];
            ak_vec3 up = ak_vec3_normalize(ak_vec3_sub(ak_mat4_transform_point(mp, P1->tail), ak_mat4_transform_point(mp, P1->head)));
            ak_vec3 uc = ak_vec3_normalize(ak_vec3_sub(ak_mat4_transform_point(mc, C1->tail), ak_mat4_transform_point(mc, C1->head)));
            if (ak_vec3_dot(up, uc) > SOFT_RELEASE_BEND_COS) continue;
        }
        const ak_vec3 o0 = P1->tail;
        const float reach = ak_maxf(ak_vec3_distance(P1->head, P1->tail), ak_vec3_distance(C1->head, C1->tail)) +
                            2.0f * ak_maxf(s->contact_radius[bp], s->contact_radius[bc]);
        for (size_t n = 0; n < nn; ++n) {
            if (!s->kinematic[n] || c->released[n]) continue;
            const uint16_t part = s->node_joints[SOFT_INFLUENCES * n];
            const bool parent = part == P1->joint_index;
            if (!parent && part != C1->joint_index) continue;
            ak_vec3 rel = ak_vec3_sub(c->target[n], o);
            float dist = ak_vec3_length(rel);
            if (dist > reach) continue;
            float sd = ak_vec3_dot(rel, nrm), own = parent ? -sd : sd;
            ak_vec3 rel0 = ak_vec3_sub(s->rest[n], o0);
            float sd0 = ak_vec3_dot(rel0, nrm0);
            if ((parent ? -sd0 : sd0) < SOFT_RELEASE_CONE * ak_vec3_length(rel0)) continue;
            if (own < SOFT_RELEASE_CONE * dist) {
                c->released[n] = parent ? (int32_t)pl + 1 : -((int32_t)pl + 1);
                c->x[n].w = s->mass[n] > 0.0f ? 1.0f / s->mass[n] : 0.0f;
                c->hold[n] = c->tether;
            }
        }
    }
    /* the parts beyond the two bones: the heel of a folded leg reaches the buttock */
    const float reach2 = (SOFT_CONTACT_REACH * s->cell) * (SOFT_CONTACT_REACH * s->cell);
    for (uint32_t pl = 0; pl < s->plane_count; ++pl) {
        if (!c->plane_active[pl]) continue;
        const ak_vec3 nrm = c->planes[2 * pl + 1], o = c->planes[2 * pl];
        for (uint32_t i = s->xnode_start[pl]; i < s->xnode_start[pl + 1]; ++i) {
            const int32_t e = s->xnode[i];
            const size_t n = (size_t)(e > 0 ? e : -e) - 1;
            if (c->released[n]) continue;
            const bool kin = s->kinematic[n] != 0;
            const ak_vec3 p = c->target[n]; /* skinned: the gate does not flicker with the flesh */
            const float own = (e > 0 ? -1.0f : 1.0f) * ak_vec3_dot(ak_vec3_sub(p, o), nrm);
            if (kin && own >= SOFT_LET_GO * s->cell) continue;
            /* a node above the upper bone meets the parts below the lower bone; one below the
             * lower bone meets the whole parent side */
            const uint32_t r0 = s->snode_start[e > 0 ? 2 * pl + 1 : 2 * pl], r1 = s->snode_start[e > 0 ? 2 * pl + 2 : 2 * pl + 1];
            bool near = false;
            for (uint32_t k = r0; k < r1 && !near; ++k) near = ak_vec3_length_sq(ak_vec3_sub(c->target[s->snode[k]], p)) < reach2;
            if (!near) continue;
            c->released[n] = e > 0 ? (int32_t)pl + 1 : -((int32_t)pl + 1);
            if (kin) { /* let go by degrees: its tether 30 rad/s / (1 - f)^2, f from 0 at half a cube to 1 at SOFT_LET_GO */
                c->x[n].w = s->mass[n] > 0.0f ? 1.0f / s->mass[n] : 0.0f;
                const float f = ak_clampf((own - 0.5f * s->cell) / ((SOFT_LET_GO - 0.5f) * s->cell), 0.0f, 0.999f);
                const float om = SOFT_TETHER_OMEGA / ((1.0f - f) * (1.0f - f)), wh2 = om * c->h * om * c->h;
                c->hold[n] = wh2 / (1.0f + wh2);
            }
        }
    }
}

ak_result ak_skin_soft_step_run(const ak_skin_soft_step_job* j) {
    ak_result r = ak_skin_soft_step_validate(j);
    if (r != AK_OK) return r;
    const ak_skin_soft* s = j->soft;
    const size_t nn = s->node_count;
    uint8_t* base = (uint8_t*)(((uintptr_t)j->scratch.ptr + 63) & ~(uintptr_t)63);
    step_ctx c;
    memset(&c, 0, sizeof c);
    c.s = s;
    c.v = j->node_velocities.ptr;
    c.x = (soft_p4*)(void*)base;
    c.prev = c.x + nn;
    c.start = (ak_vec3*)(void*)(c.prev + nn);
    c.target = c.start + nn;
    c.vref = c.target + nn;
    c.lambda = (float*)(void*)((uint8_t*)c.start + akp_align16(3 * nn * sizeof(ak_vec3)));
    c.bones = (posed_bone*)(void*)((uint8_t*)c.lambda + akp_align16(2 * s->tet_count * sizeof(float)));
    c.seg = (ak_vec3*)(void*)((uint8_t*)c.bones + akp_align16(s->bone_count * sizeof(posed_bone)));
    const size_t plane_bytes = akp_align16(2 * s->plane_count * sizeof(ak_vec3));
    c.planes = (ak_vec3*)(void*)((uint8_t*)c.seg + akp_align16(4 * s->bone_count * sizeof(ak_vec3)));
    c.planes0 = (ak_vec3*)(void*)((uint8_t*)c.planes + plane_bytes);
    c.psub = (ak_vec3*)(void*)((uint8_t*)c.planes0 + plane_bytes);
    c.released = (int32_t*)(void*)((uint8_t*)c.psub + plane_bytes);
    c.plane_active = (uint8_t*)c.released + akp_align16(nn * sizeof(int32_t));
    c.hold = (float*)(void*)(c.plane_active + akp_align16(s->plane_count + 1));
    float dt = j->dt > 0.0f ? j->dt : 1.0f / 60.0f;
    c.h = dt / (float)s->substeps;
    c.gamma = s->damping / c.h;
    c.iterations = 1;
    c.adev = 1.0f / (s->mu * c.h * c.h);
    c.ahyd = 1.0f / (s->lambda * c.h * c.h);
    c.hyd_rest = 1.0f + s->mu / s->lambda;
    c.gravity = j->gravity;
#if SOFT_SIMD
    c.simd = __builtin_cpu_supports("avx2");
#endif
    c.jiggle = 1.0f - expf(-s->jiggle_damping * c.h);
    {
        const float wh2 = SOFT_TETHER_OMEGA * c.h * SOFT_TETHER_OMEGA * c.h;
        c.tether = wh2 / (1.0f + wh2);
    }
    const bool have_prev = j->previous_palette.ptr != NULL;
    for (size_t n = 0; n < nn; ++n) {
        c.start[n] = j->node_positions.ptr[n];
        c.x[n] = (soft_p4){c.start[n], s->inv_mass[n]};
        ak_vec3 end = lbs_node(s, n, j->palette.ptr, j->palette.count);
        c.target[n] = end; /* kinematic: where it goes; flesh: the contact gate (release_nodes) */
        c.vref[n] = have_prev ? ak_vec3_scale(ak_vec3_sub(end, lbs_node(s, n, j->previous_palette.ptr, j->previous_palette.count)), 1.0f / dt)
                              : ak_vec3_zero();
    }
    /* the colliders at the step's end, and at its start (the previous palette; without one,
     * the end's: they do not move within the step) */
    for (int end = 1; end >= 0; --end) {
        const ak_mat4* pal = end || !have_prev ? j->palette.ptr : j->previous_palette.ptr;
        for (size_t b = 0; b < s->bone_count; ++b) {
            size_t jn = s->bones[b].joint_index;
            c.seg[4 * b + 2 * (size_t)end] = ak_mat4_transform_point(pal[jn], s->bones[b].head);
            c.seg[4 * b + 2 * (size_t)end + 1] = ak_mat4_transform_point(pal[jn], s->bones[b].tail);
        }
        ak_vec3* planes = end ? c.planes : c.planes0;
        for (uint32_t pl = 0; pl < s->plane_count; ++pl) {
            const ak_skin_bone *bp = &s->bones[s->planes[2 * pl]], *bc = &s->bones[s->planes[2 * pl + 1]];
            const ak_mat4 mp = pal[bp->joint_index], mc = pal[bc->joint_index];
            ak_vec3 up = ak_vec3_normalize(ak_vec3_sub(ak_mat4_transform_point(mp, bp->tail), ak_mat4_transform_point(mp, bp->head)));
            ak_vec3 uc = ak_vec3_normalize(ak_vec3_sub(ak_mat4_transform_point(mc, bc->tail), ak_mat4_transform_point(mc, bc->head)));
            ak_vec3 u = ak_vec3_add(up, uc);
            planes[2 * pl] = ak_mat4_transform_point(mp, bp->tail);
            /* folded: off (|u| = 2 cos(a / 2) at an angle a between the bones: 0.05 is 177.1 deg) */
            planes[2 * pl + 1] = ak_vec3_length(u) > 0.05f ? plane_normal(s->plane_bisector[pl], mp, mc, u) : ak_vec3_zero();
            if (end) c.plane_active[pl] = !s->plane_bent0[pl] && ak_vec3_length(u) > 0.05f && ak_vec3_dot(up, uc) <= SOFT_RELEASE_BEND_COS;
        }
    }
    release_nodes(s, &c, j->palette.ptr);
    uint32_t tc = j->thread_count > 1 ? j->thread_count : 1;
    /* a barrier per colour and substep costs microseconds; the AVX2 solve of a colour of a
     * few-thousand-node lattice takes about as long: threads only from SOFT_NODES_PER_THREAD */
    if (tc > 1 && nn < SOFT_NODES_PER_THREAD * (size_t)tc)
        tc = (uint32_t)(nn / SOFT_NODES_PER_THREAD > 1 ? nn / SOFT_NODES_PER_THREAD : 1);
    soft_team team;
    team.c = &c;
    team.count = 1;
    team.go = 0;
    if (tc > 1 && pthread_mutex_init(&team.mutex, NULL) == 0) {
        if (pthread_cond_init(&team.cond, NULL) == 0) {
            soft_worker w[64];
            pthread_t ids[64];
            uint32_t started = 1;
            for (; started < tc; ++started) {
                w[started] = (soft_worker){&team, started};
                if (pthread_create(&ids[started], NULL, step_thread, &w[started]) != 0) break;
            }
            pthread_mutex_lock(&team.mutex);
            team.count = started;
            team.go = started > 1 && pthread_barrier_init(&team.barrier, NULL, started) == 0 ? 1 : -1;
            if (team.go < 0) team.count = 1;
            pthread_cond_broadcast(&team.cond);
            pthread_mutex_unlock(&team.mutex);
            step_work(&team, 0);
            for (uint32_t i = 1; i < started; ++i) pthread_join(ids[i], NULL);
            if (team.go > 0) pthread_barrier_destroy(&team.barrier);
            pthread_cond_destroy(&team.cond);
        } else {
            step_work(&team, 0);
        }
        pthread_mutex_destroy(&team.mutex);
    } else {
        step_work(&team, 0);
    }
    bool finite = true;
    double ke = 0.0;
    for (size_t n = 0; n < nn; ++n) j->node_positions.ptr[n] = c.x[n].p;
    for (size_t n = 0; n < nn && finite; ++n) {
        finite = ak_vec3_is_finite(c.x[n].p) && ak_vec3_is_finite(c.v[n]);
        if (!s->kinematic[n] || c.released[n]) ke += 0.5 * (double)s->mass[n] * (double)ak_vec3_length_sq(c.v[n]);
    }
    if (!finite) {
        (void)ak_skin_soft_state_init(s, j->palette, j->node_positions, j->node_velocities);
        ke = 0.0;
    }
    if (j->out_positions.ptr) surface_range(s, j->node_positions.ptr, j->out_positions.ptr, 0, s->vertex_count);
    if (j->out_kinetic_energy) *j->out_kinetic_energy = (float)ke;
    return AK_OK;
}
