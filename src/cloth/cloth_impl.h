/* Private layout of an ak_cloth, shared by cloth.c (building, measures) and step.c. */
#ifndef ANIMKIT_CLOTH_IMPL_H
#define ANIMKIT_CLOTH_IMPL_H

#include <animkit/cloth.h>

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
    uint32_t* lra_anchor; /* [n] nearest kinematic particle, UINT32_MAX -> none; NULL when off */
    float* lra_dist;      /* [n] allowed distance */
    uint32_t* vt_start;   /* [n + 1] CSR: triangles around each vertex */
    uint32_t* vt_tri;     /* [3 tri_count] */
};

/* Dihedral angle of a bending element and its gradient (grad NULL -> angle only). */
float akp_dihedral(const ak_vec3 x[4], ak_vec3 grad[4]);

#endif
