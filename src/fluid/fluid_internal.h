/* Internals of the fluid module shared by src/fluid.c and its SIMD kernels (never installed).
 *
 * Each step works in "sorted space": the particles re-sorted by grid cell (cells in (z, y, x)
 * order when the liquid's bounding box is compact, the shared grid's hashed order otherwise),
 * predicted positions as SoA, neighbour lists holding sorted indices. Sorting is by position
 * only, so it never depends on the thread count. */
#ifndef ANIMKIT_FLUID_INTERNAL_H
#define ANIMKIT_FLUID_INTERNAL_H

#include <animkit/fluid.h>
#include <animkit/grid.h>

#define AKP_FLUID_MAX_THREADS 64u

typedef struct akp_fluid_ctx {
    ak_fluid_desc d;
    const ak_fluid_step_job* job;
    size_t n;
    float dt, h, h2, rho0, m, mr; /* mr = m / rho0 */
    uint32_t K, full_lattice_count;
    ak_fluid_kernels kernels; /* the kernel set of this step (never BEST) */
    bool simd;                /* kernels is AVX2 or AVX-512: records p4/q4 and padded lists kept */
    /* original order (the caller's arrays) */
    ak_vec3* xo;   /* positions */
    ak_vec3* vo;   /* velocities */
    ak_vec3* pred; /* predicted positions, original order */
    /* sorted space */
    uint32_t* order;     /* [n]: original index of sorted particle a */
    uint32_t* cell;      /* [n]: dense cell of original particle i (counting sort) */
    float *px, *py, *pz; /* predicted positions (PBF: the current Jacobi iterate) */
    float *qx, *qy, *qz; /* the next Jacobi iterate (PBF) / the integrated positions (SPH) */
    float *p4, *q4;      /* SIMD kernels, 16-byte records (one load each): p4 = (p, 0), the
                            current iterate (the correction pass writes the next one there, reading
                            none); q4 = (p, lambda) from the lambda pass for the correction pass,
                            then (v, rho) for vorticity and XSPH */
    ak_vec3* x0;         /* start-of-step positions */
    ak_vec3* v;          /* velocities */
    ak_vec3* acc;        /* SPH accelerations */
    ak_vec3* omega;      /* vorticity */
    float* omega_len;    /* |omega| */
    ak_vec3* vnew;
    float *lambda, *rho, *pres;
    uint32_t *nb_count, *nb; /* lists of sorted indices, slot-major blocks (akp_fluid_nb) */
    uint32_t* tbuf;          /* [threads][K + 16]: a list being built */
    uint8_t* flags;
    /* neighbour search */
    ak_grid grid;     /* hashed fallback */
    uint32_t* dstart; /* dense path: [volume + 1] first sorted index of each (z, y, x) cell */
    int64_t cmin[3];  /* dense path: cell coordinates of the box's first cell */
    int64_t dim[3];   /* dense path: cells per axis */
    double inv_cell;  /* 1 / h in double (the grid's cell formula) */
    float rho_c;      /* PBF: the density the constraint holds, m sum_j W_poly6 over the rest lattice */
    float coincident2; /* squared distance below which two particles count as coincident */
    float wdq;        /* poly6 at delta q */
    float grad2_rest; /* sum_k |grad_k C|^2 of the rest lattice */
    float poly6_k;    /* 315 / (64 pi h^9) */
    float spiky_k;    /* -45 / (pi h^6) */
    float inv_h;      /* 1 / h */
    float cubic_k;    /* 8 / (pi h^3) */
    float cubic_gk;   /* 48 / (pi h^4) */
    float visc_lap_k; /* 45 / (pi h^6): ak_fluid_visc_laplacian(r, h) = visc_lap_k (h - r) */
    struct akp_fluid_team* team; /* fluid.c: the step's worker team (NULL: the caller alone) */
    /* per-thread results */
    size_t truncated[AKP_FLUID_MAX_THREADS];
    size_t coincident[AKP_FLUID_MAX_THREADS];
    float box_lo[AKP_FLUID_MAX_THREADS][3], box_hi[AKP_FLUID_MAX_THREADS][3]; /* predictions' bounds */
    bool box_bad[AKP_FLUID_MAX_THREADS];                                       /* a non-finite one */
    struct akp_csort* csort; /* fluid.c: the dense cell sort over the team */
    struct akp_fluid_stats_part* stats; /* fluid.c: the statistics' partials per chunk */
} akp_fluid_ctx;

/* Neighbour q of sorted particle a is akp_fluid_nb(c, a)[16 q]: particles come in blocks of
 * 16, each block storing slot q of its 16 lists in 16 consecutive entries (one load gives the
 * q-th neighbours of 16 particles to the AVX-512 kernels). */
static inline const uint32_t* akp_fluid_nb(const akp_fluid_ctx* c, size_t a) {
    return c->nb + (a >> 4) * c->K * 16 + (a & 15);
}

/* avx512.c (x86-64 GCC/Clang without AK_NO_SIMD; elsewhere have_avx512 is false and the
 * kernels are never called). Each handles sorted particles [b, e) like its scalar phase in
 * fluid.c, 16 particles at a time (one per lane), each summing its neighbours in list order
 * with the scalar phase's float operations: results are bit-identical to the scalar phases. */
bool akp_fluid_have_avx512(void);
/* Appends to list[*k] (capacity K) the candidates [begin, end) closer than h to (qx, qy, qz),
 * in index order; returns the number found (also those beyond K) and adds to *close those
 * closer than sqrt(coincident2) (the particle itself included). */
uint32_t akp_fluid_filter_avx512(const akp_fluid_ctx* c, uint32_t begin, uint32_t end, float qx,
                                 float qy, float qz, uint32_t* list, uint32_t* k, uint32_t* close);
void akp_fluid_density_avx512(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_lambda_avx512(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_delta_avx512(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_vorticity_avx512(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_xsph_avx512(akp_fluid_ctx* c, size_t b, size_t e);
/* SPH / WCSPH: WCSPH's cubic-spline density pass and the force pass (ph_forces: MCG pressure and
 * viscosity Laplacian, or WCSPH pressure with the artificial viscosity). The force kernels read
 * (v, rho) records from q4 and the pressures from p4's w (ph_pack_forces). */
void akp_fluid_density_cubic_avx512(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_forces_avx512(akp_fluid_ctx* c, size_t b, size_t e);

/* avx2.c: the same kernels on 8 lanes (each block of 16 as two halves), bit-identical too. */
bool akp_fluid_have_avx2(void);
uint32_t akp_fluid_filter_avx2(const akp_fluid_ctx* c, uint32_t begin, uint32_t end, float qx,
                               float qy, float qz, uint32_t* list, uint32_t* k, uint32_t* close);
void akp_fluid_density_avx2(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_lambda_avx2(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_delta_avx2(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_vorticity_avx2(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_xsph_avx2(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_density_cubic_avx2(akp_fluid_ctx* c, size_t b, size_t e);
void akp_fluid_forces_avx2(akp_fluid_ctx* c, size_t b, size_t e);

/* fluid.c: the collision projection of every solver (v may be NULL); the scalar tails shared
 * by every kernel set: the corrected position p of particle i collided and stored as the next
 * iterate, and particle i's XSPH and vorticity-confinement velocity from its sums. */
void akp_fluid_collide(const akp_fluid_ctx* c, ak_vec3* p, ak_vec3* v);
void akp_fluid_delta_finish(akp_fluid_ctx* c, size_t i, ak_vec3 p);
void akp_fluid_xsph_finish(akp_fluid_ctx* c, size_t i, ak_vec3 eta, ak_vec3 xs);
/* SPH / WCSPH: particle i's acceleration from its force sum a (SPH divides by rho_i). */
void akp_fluid_forces_finish(akp_fluid_ctx* c, size_t i, ak_vec3 a);

#endif
