/* Shared between the skin module's .c files; never installed. */
#ifndef ANIMKIT_SKIN_INTERNAL_H
#define ANIMKIT_SKIN_INTERNAL_H

#include <animkit/skin.h>

#include "../internal.h"

/* Per-joint data prepared once per run for DQS and CoR (lives in the job's scratch). */
typedef struct akp_skin_joint {
    float real[4];    /* rotation quaternion of the rigid part (x, y, z, w) */
    float dual[4];    /* 0.5 * t * real */
    union {
        struct {
            float stretch[12]; /* S = R^T A, three columns padded to 4 floats */
            float pad[12];
        };
        /* CoR when no joint has stretch (stretch is then unused): the palette matrix's four
         * columns (x, y, z) with real[0..3] in their w slots, so that one blend of two 8-float
         * rows gives both the matrix and the rotation (filled by ak_skin_job_run) */
        float cor_rows[16];
    };
} akp_skin_joint;

/* CoR without stretch: after the palette.count joints, the scratch holds palette.count more
 * copies of cor_rows with the rotation negated (64 bytes each, akp_skin_cor_neg_rows), so the
 * AVX2 kernel applies the hemisphere sign by choosing a copy instead of per-influence blends. */
static inline float* akp_skin_cor_neg_rows(akp_skin_joint* prep, size_t palette_count, size_t j) {
    return (float*)(void*)((char*)(prep + palette_count) + 64 * j);
}

/* Resolved view of a job for one vertex range; pointers already offset to vertex 0. */
typedef struct akp_skin_ctx {
    ak_skin_method method;
    uint32_t k;                    /* influence count */
    const ak_mat4* palette;
    size_t palette_count;
    const akp_skin_joint* joints_prep; /* DQS/CoR only (CoR: then the negated rows) */
    bool any_stretch;              /* some joint has scale or shear */
    const char *pos, *nrm, *tan, *jnt, *wgt, *ctr;
    size_t pos_stride, nrm_stride, tan_stride, jnt_stride, wgt_stride, ctr_stride;
    char *out_pos, *out_nrm, *out_tan;
    size_t out_pos_stride, out_nrm_stride, out_tan_stride;
    bool do_normals, do_tangents;
    /* LBS with 1 influence, no tangents, and no normals or every palette matrix rigid
     * (orthonormal linear part, det > 0, within 1e-5): the SIMD kernels may skip the blend
     * (p' = w (M p)) and the normal's cofactor and renormalisation (n' = sign(w) R n); the
     * results then differ from the scalar code's by float rounding */
    bool rigid_single;
} akp_skin_ctx;

/* Deform vertices [begin, end) with the scalar reference code. */
void akp_skin_range_scalar(const akp_skin_ctx* c, size_t begin, size_t end);
/* Deform [begin, end) with the AVX2 kernel when this CPU and configuration allow it; returns
 * false (writing nothing) when it cannot handle the configuration. */
bool akp_skin_range_avx2(const akp_skin_ctx* c, size_t begin, size_t end);
/* True when the AVX2 kernel is compiled in and the CPU supports AVX2 and FMA. */
bool akp_skin_have_avx2(void);
/* The same for the AVX-512 kernel (deform_avx512.c: 16 vertices per block, partial blocks
 * masked, so it handles any range): AVX-512 F, VL, DQ, BW plus AVX2 and FMA. */
bool akp_skin_range_avx512(const akp_skin_ctx* c, size_t begin, size_t end);
bool akp_skin_have_avx512(void);

/* Closest-point distance squared from p to the segment [a, b] (a == b allowed). */
static inline float akp_segment_dist_sq(ak_vec3 p, ak_vec3 a, ak_vec3 b, ak_vec3* out_closest) {
    ak_vec3 ab = ak_vec3_sub(b, a);
    float len2 = ak_vec3_dot(ab, ab);
    float t = len2 > 0.0f ? ak_clampf(ak_vec3_dot(ak_vec3_sub(p, a), ab) / len2, 0.0f, 1.0f) : 0.0f;
    ak_vec3 c = ak_vec3_madd(a, ab, t);
    if (out_closest) *out_closest = c;
    return ak_vec3_length_sq(ak_vec3_sub(p, c));
}

/* Per-vertex post-processing shared by the weight methods: dense[joint_count] holds raw
 * weights (>= 0); writes the k largest (after dropping those below min_weight relative to
 * the total) renormalised to sum 1, sorted decreasing; fallback_joint gets 1 when all vanish. */
void akp_weights_finish(const double* dense, size_t joint_count, uint32_t k, float min_weight,
                        uint16_t fallback_joint, uint16_t* out_joints, float* out_weights);

/* 64-bit FNV-1a over bytes, continuing from h. */
static inline uint64_t akp_fnv1a(uint64_t h, const void* data, size_t size) {
    const unsigned char* p = (const unsigned char*)data;
    for (size_t i = 0; i < size; ++i) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

/* Little-endian helpers for the file formats. */
static inline void akp_put_u32(unsigned char* p, uint32_t v) {
    p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24);
}
static inline uint32_t akp_get_u32(const unsigned char* p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline void akp_put_f32(unsigned char* p, float f) {
    uint32_t v;
    memcpy(&v, &f, 4);
    akp_put_u32(p, v);
}
static inline float akp_get_f32(const unsigned char* p) {
    uint32_t v = akp_get_u32(p);
    float f;
    memcpy(&f, &v, 4);
    return f;
}

/* Implicit skinning's Newton march (implicit.c's project) for up to 16 vertices at once: the
 * kernels (implicit_avx2.c, 8 lanes; implicit_avx512.c, 16 lanes) find each point's broad-phase
 * cell, evaluate the field there (per bone: its grid, nodes of 4 floats, distance and gradient;
 * grid_info nx ny nz first node; its per-frame record of bf_floats floats, implicit.c's
 * bone_frames_build; its inverse palette matrix, 12 floats) and take one Newton step. A kernel
 * does per lane the scalar code's operations in the same order (no fused multiply-add), so the
 * results are bitwise the scalar path's. */
typedef struct akp_implicit_field {
    const float* grid;
    const uint32_t* grid_info;
    const float* bf;
    const float* inv;
    uint32_t bf_floats;
    float bulge;
    /* the broad phase: box corner, cells per unit, cells per axis, one mask word per cell
     * (NULL: empty, the field is 0 everywhere) */
    float bp_lo[3], bp_inv_cell[3];
    uint32_t bp_cells;
    const uint64_t* bp_mask;
    /* the march: steps at most, |F - iso| that ends it, the cosine of the gradient turn that
     * stops it, the longest step, |F - iso| below which a step is the last */
    float iterations, iso_eps, stop_cos, step_cap, unchecked_below;
} akp_implicit_field;

/* The lanes of one call, each a march in progress: its point (x, y, z), iso-value, previous
 * gradient (px, py, pz), steps taken (it) and state (st: implicit.c's ST_KEEP, ST_MOVED,
 * ST_STOPPED), all floats; the kernel leaves the gradient at the point's last evaluation in
 * (gx, gy, gz), and cell, mask and f as scratch. */
typedef struct akp_implicit_lanes {
    _Alignas(64) float x[16];
    _Alignas(64) float y[16];
    _Alignas(64) float z[16];
    _Alignas(64) float iso[16];
    _Alignas(64) float px[16];
    _Alignas(64) float py[16];
    _Alignas(64) float pz[16];
    _Alignas(64) float it[16];
    _Alignas(64) float st[16];
    _Alignas(64) float f[16];
    _Alignas(64) float gx[16];
    _Alignas(64) float gy[16];
    _Alignas(64) float gz[16];
    _Alignas(64) int32_t cell[16];
    uint64_t mask[16];
} akp_implicit_lanes;

/* One evaluation and Newton step of the live lanes (bit l: lane l) of l, 16 (AVX-512) or 8
 * (AVX2); returns the lanes whose march ended (implicit.c's march_step returned true). 0 where
 * this build has no such kernel: callers check akp_skin_have_avx512 / akp_skin_have_avx2. */
unsigned akp_implicit_march_avx512(const akp_implicit_field* fd, akp_implicit_lanes* l, unsigned live);
unsigned akp_implicit_march_avx2(const akp_implicit_field* fd, akp_implicit_lanes* l, unsigned live);

#endif
