/* Internal kernels of the neighbour grid. Never installed. */
#ifndef ANIMKIT_GRID_INTERNAL_H
#define ANIMKIT_GRID_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <animkit/grid.h>

/* Sorted entries [begin, end) of one neighbour cell. */
typedef struct akp_grid_range {
    uint32_t begin, end;
} akp_grid_range;

/* One row of the neighbour lists: the entries b of the ranges (in order) other than `self`
 * with dx*dx + dy*dy + dz*dz < r2, dx = x[b] - qx etc. (the module's test, float, no FMA).
 * out NULL: returns the count; otherwise writes order[b] of each hit to out and returns the
 * count. The AVX-512 kernel (akp_grid_have_avx512) gives exactly the scalar kernel's result. */
size_t akp_grid_row_scalar(const float* x, const float* y, const float* z, const uint32_t* order,
                           const akp_grid_range* ranges, uint32_t range_count, uint32_t self,
                           float qx, float qy, float qz, float r2, uint32_t* out);
bool akp_grid_have_avx512(void);
size_t akp_grid_row_avx512(const float* x, const float* y, const float* z, const uint32_t* order,
                           const akp_grid_range* ranges, uint32_t range_count, uint32_t self,
                           float qx, float qy, float qz, float r2, uint32_t* out);

/* The pairs (order[a], order[b]) as (min, max), a in [a0, a1), b in [b(a), b1) with b(a) =
 * a + 1 when same, else b0, whose distance passes the test, in (a, b) order, written at out
 * (room for every candidate needed); returns the count. Exactly grid.c's scalar pair loop. */
size_t akp_grid_pairs_avx512(const float* x, const float* y, const float* z, const uint32_t* order,
                             uint32_t a0, uint32_t a1, uint32_t b0, uint32_t b1, bool same, float r2,
                             ak_grid_pair* out);

#endif
