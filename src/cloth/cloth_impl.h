/* Private layout of an ak_cloth, shared by cloth.c (building, measures) and step.c. */
#ifndef ANIMKIT_CLOTH_IMPL_H
#define ANIMKIT_CLOTH_IMPL_H

#include <animkit/cloth.h>

/* The solvers that integrate forces of springs (no constraints, no multipliers). */
static inline bool akp_spring_solver(ak_cloth_solver s) { return s == AK_CLOTH_SPRINGS || s == AK_CLOTH_IMPLICIT; }

/* Kinds of distance constraint (springs). */
enum { AKP_STRETCH = 0, AKP_SHEAR = 1, AKP_BEND = 2 };

/* Constraints of colour c are [color_start[c], color_start[c + 1]); no two of one colour share a
 * particle, except in the last colour (AKP_SERIAL_COLOR), which one thread solves in order. */
#define AKP_MAX_COLORS 64
#define AKP_SERIAL_COLOR AKP_MAX_COLORS

typedef struct akp_dist {
    uint32_t i, j;
    float rest;   /* metres */
    float k;      /* N/m (INFINITY: rigid) */
    float alpha;  /* compliance 1/k (m/N) */
    uint32_t kind;
} akp_dist;

/* Dihedral bending of the edge (p[2], p[3]) between triangles (p[2], p[3], p[0]) and
 * (p[3], p[2], p[1]) (both counter-clockwise). */
typedef struct akp_bend {
    uint32_t p[4];
    float rest;   /* dihedral: rest angle (radians); isometric: |b| at rest (m) */
    float K[4];   /* isometric: cotangent weights of p[0..3] */
    float alpha;  /* isometric: compliance (A0 + A1) / (3 k) */
} akp_bend;

struct ak_cloth {
    ak_cloth_desc desc; /* resolved; spans point at the copies below */
    ak_allocator alloc;
    size_t n, tri_count, dist_count, bend_count, attach_count, pin_count;
    ak_vec3* rest;      /* [n] */
    float* inv_mass;    /* [n] after pins and attachments */
    float* mass;        /* [n] 0 where kinematic */
    uint32_t* indices;  /* [3 tri_count] */
    uint32_t* pins;     /* [pin_count] */
    ak_vec3* pin_pos;   /* [pin_count] */
    uint32_t* attach;   /* [attach_count] */
    akp_dist* dist;     /* [dist_count], by colour */
    uint32_t dist_color[AKP_MAX_COLORS + 2];
    akp_bend* bend;     /* [bend_count], by colour */
    uint32_t bend_color[AKP_MAX_COLORS + 2];
    /* the same constraints as structures of arrays (the solvers' layout, cloth_kernel.h) */
    uint32_t *dist_i, *dist_j;  /* [dist_count] */
    float *dist_rest, *dist_alpha;
    uint32_t* bend_p[4];        /* [bend_count] each */
    float* bend_K[4];           /* isometric weights; NULL unless isometric */
    float *bend_rest, *bend_alpha; /* bend_alpha: isometric compliance; NULL unless isometric */
    uint32_t* lra_anchor; /* [n] nearest kinematic particle, UINT32_MAX -> none; NULL when off */
    float* lra_dist;      /* [n] allowed distance */
    uint32_t* vt_start;   /* [n + 1] CSR: triangles around each vertex */
    uint32_t* vt_tri;     /* [3 tri_count] */
    float stable_h;       /* the spring solver's largest stable substep (s), INFINITY: none */
};

/* Dihedral angle of a bending element (wings x0, x1, edge x2 -> x3) and its gradient (grad NULL
 * -> angle only); 0 and a zero gradient for a degenerate element. The step's own formula. */
float akp_dihedral(const ak_vec3 x[4], ak_vec3 grad[4]);

/* A particle in the step's working copy: its displacement since the start of the step (the
 * caller's positions) and its inverse mass in 16 bytes, so that a SIMD solve loads or stores one
 * particle with one 128-bit access. Displacements are small, so float resolves a substep's
 * motion (g h^2 is 1e-7 m at h = 1e-4 s) wherever the cloth is. */
typedef struct akp_px {
    ak_vec3 p;
    float w;
} akp_px;

/* What the constraint solves (cloth_kernel.h) read besides the cloth. */
typedef struct akp_solve {
    const ak_cloth* cl;
    akp_px* x;
    const akp_px* prev;   /* displacements at the start of the substep (read when damped) */
    float* dist_off[3];   /* x_i - x_j of distance constraint k at the start of the step (x, y, z) */
    float* bend_off[9];   /* dihedral: x3 - x2, x0 - x2, x1 - x2 of bending constraint k at the start
                             of the step; isometric: [0..2] sum_{q != 2} K_q (x_q - x_2) */
    float* lambda;        /* [dist_count + bend_count] multipliers */
    float h, h2, beta;    /* substep, its square, constraint damping (s) */
    float pbd_stiffness;  /* PBD factor */
    float bend_alpha;     /* dihedral compliance 1 / dihedral_stiffness */
    bool pbd, damped, iso;
} akp_solve;

/* SIMD solves of the constraints of one colour from b on, in whole blocks (8 or 16): return
 * where they stopped (the rest, fewer than a block, is the caller's). Only built for x86-64
 * GCC/clang without AK_NO_SIMD; the have_ functions say whether this CPU runs them. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#define AKP_CLOTH_SIMD 1
bool akp_cloth_have_avx2(void);
bool akp_cloth_have_avx512(void);
size_t akp_cloth_dist_avx2(const akp_solve* s, size_t b, size_t e, bool first);
size_t akp_cloth_bend_avx2(const akp_solve* s, size_t b, size_t e, bool first);
size_t akp_cloth_dist_avx512(const akp_solve* s, size_t b, size_t e, bool first);
size_t akp_cloth_bend_avx512(const akp_solve* s, size_t b, size_t e, bool first);
#else
#define AKP_CLOTH_SIMD 0
#endif

#endif
