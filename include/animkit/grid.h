/* animkit grid: uniform-grid neighbour search over a point cloud (particles, boids, cloth).
 *
 * What it does: sorts points into cubic cells of edge cell_size (a radix sort on the Morton
 * code of each point's cell, so a cell's points are contiguous and cells near in space are
 * near in memory; a hash table finds a cell from its coordinates, so points anywhere work: no
 * bounds to declare, no point is "outside"), then answers, for a radius r, every point within
 * r of a query point (ak_grid_query), every pair of points closer than r (ak_grid_pairs_run)
 * and every point's neighbour list in CSR form (ak_grid_neighbors_run). All return exactly the
 * brute-force set under the one distance test the whole module uses:
 *
 *     dx = pj.x - q.x, dy = pj.y - q.y, dz = pj.z - q.z   (float)
 *     neighbour  <=>  dx*dx + dy*dy + dz*dz < r*r         (float, strict <)
 *
 * (for pairs, q = p_i; a brute-force loop that evaluates this expression gets the same set).
 * Cells are best sized to the query radius (cell_size = r): each query then visits the 27
 * cells around it, and all pairs visit each cell's 13 forward neighbours once. Any r > 0 works
 * with any cell_size: a larger r visits more rings of cells.
 *
 * What it does NOT do: allocate (the caller passes memory sized by ak_grid_memory_size),
 * update incrementally (rebuild each step: a build is a linear-time pass), or k-nearest
 * queries. Positions must be finite (NaN or infinity -> AK_ERR_BAD_DATA).
 *
 * Usage:
 *     ak_grid_desc gd = {.cell_size = r};
 *     size_t bytes = ak_grid_memory_size(n, &gd);
 *     void* mem = malloc(bytes);
 *     ak_grid grid;
 *     ak_grid_build(&gd, (ak_vec3_cspan){pos, n}, (ak_u8_span){mem, bytes}, &grid);
 *     uint32_t near[64];
 *     size_t k = ak_grid_query(&grid, q, r, (ak_u32_span)AK_SPAN(near)); // total, may be > 64
 *     size_t pair_count = 0;
 *     ak_grid_pairs_job job = {.grid = &grid, .radius = r, .out_pairs = {pairs, cap},
 *                              .out_pair_count = &pair_count, .thread_count = 2};
 *     if (ak_grid_pairs_run(&job) == AK_ERR_SPAN_SMALL) { grow pairs to pair_count, rerun }
 *
 * The pair and list passes test 8 or 16 candidates at a time with AVX-512 where the CPU has
 * it (chosen at run time; the same float operations, so the same output as the scalar loops).
 *
 * Hot loops can walk the sorted layout directly: grid.x/y/z[k] is the k-th point in sorted
 * order (original index grid.order[k]); cell m holds sorted entries [cell_start[m],
 * cell_start[m+1]) and has integer coordinates cell_coord[m]; ak_grid_cell_find maps a cell
 * coordinate to its m.
 *
 * Ownership and threading: ak_grid_build keeps no pointer to the input points (it copies them
 * in sorted order); the ak_grid points into the caller's memory, which must outlive it. A
 * built grid is read-only: any number of threads may query it at once. ak_grid_pairs_run
 * splits the cells over thread_count threads; its output is identical for any thread count.
 */
#ifndef ANIMKIT_GRID_H
#define ANIMKIT_GRID_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Integer cell coordinates: floor(p / cell_size) per axis (computed in double precision),
 * clamped to [-2^30, 2^30] (clamping keeps far-away points correct; they only share cells). */
typedef struct ak_grid_cell {
    int32_t x, y, z;
} ak_grid_cell;

/* A pair of original point indices, i < j. */
typedef struct ak_grid_pair {
    uint32_t i, j;
} ak_grid_pair;

AK_DEFINE_SPAN(grid_pair, ak_grid_pair)

/* One entry of the grid's hash index: an occupied cell and its index m. */
typedef struct ak_grid_bucket_entry {
    ak_grid_cell cell;
    uint32_t index;
} ak_grid_bucket_entry;

/* The order of the cells in a built grid (what every pass that walks cells m = 0, 1, ... sees). */
typedef enum ak_grid_cell_order {
    /* Morton (z-curve) order of the cell coordinates minus the lowest occupied cell per axis:
     * cells near in space are near in memory, which keeps big grids in cache. When occupied
     * cells span 2^21 or more on an axis, the code of the offsets shifted right until they fit
     * (cells sharing that code follow in (z, y, x) order). */
    AK_GRID_ORDER_MORTON = 0,
    /* Grouped by hash bucket (ties in (z, y, x) order): the layout of animkit before the Morton
     * order, kept for callers whose results depend on the visit order (a Gauss-Seidel pass). */
    AK_GRID_ORDER_HASH = 1
} ak_grid_cell_order;

typedef struct ak_grid_desc {
    float cell_size; /* required, > 0 and finite: cell edge in the points' units; best = radius */
    ak_grid_cell_order cell_order; /* 0 = AK_GRID_ORDER_MORTON; anything else not listed -> BAD_ARG */
} ak_grid_desc;

/* A built grid: every array points into the memory given to ak_grid_build. Read-only. */
typedef struct ak_grid {
    float cell_size;       /* as in the desc */
    uint32_t point_count;  /* points sorted */
    uint32_t cell_count;   /* occupied cells (<= point_count) */
    uint32_t bucket_count; /* hash table size, a power of two */
    const uint32_t* order; /* [point_count]: original index of the k-th sorted point */
    const float* x;        /* [point_count]: sorted positions, SoA */
    const float* y;
    const float* z;
    const uint32_t*
        cell_start; /* [cell_count + 1]: cell m = sorted [cell_start[m], cell_start[m+1]) */
    const ak_grid_cell* cell_coord; /* [cell_count]: integer coordinates of cell m */
    const uint32_t* bucket_start; /* [bucket_count + 1]: bucket b = bucket_entry[bucket_start[b]
                                     .. bucket_start[b + 1]) */
    const ak_grid_bucket_entry* bucket_entry; /* [cell_count]: the hash index of the cells */
    /* When the box of occupied cells has at most 4 cells per point, a dense table replaces the
     * hash index (bucket_count is then 0): cell (x, y, z) of the box is m = dense[((z - oz) *
     * dy + y - oy) * dx + x - ox] (UINT32_MAX when empty), origin (ox, oy, oz), dims (dx, dy,
     * dz). NULL otherwise. Either way ak_grid_cell_find answers. */
    const uint32_t* dense;
    ak_grid_cell dense_origin;
    uint32_t dense_dim[3];
} ak_grid;

/* Bytes of memory ak_grid_build needs for point_count points (any alignment is fine; the
 * size includes the slack to align). 0 when point_count >= 2^31 or desc is NULL. */
AK_API size_t ak_grid_memory_size(size_t point_count, const ak_grid_desc* desc);

/* Sort points into the grid. memory.count >= ak_grid_memory_size(points.count, desc); the
 * memory is the grid's storage until the caller reuses it. Order inside the grid: cells in
 * desc->cell_order, points of a cell in increasing original index (so the layout is a pure
 * function of the points and the desc). points.count == 0 builds an empty grid.
 * Returns AK_ERR_NULL_ARG (desc, out_grid, memory.ptr, or points.ptr with count > 0),
 * AK_ERR_BAD_ARG (cell_size not > 0 and finite, cell_order not listed, or 2^31 points or more), AK_ERR_SPAN_SMALL
 * (memory too small), AK_ERR_BAD_DATA (a NaN or infinite coordinate). On error *out_grid is
 * an empty grid. */
AK_API ak_result ak_grid_build(const ak_grid_desc* desc, ak_vec3_cspan points, ak_u8_span memory,
                               ak_grid* out_grid);

/* The cell holding p (floor(p / cell_size), clamped as ak_grid_cell says; a NaN coordinate
 * gives -2^30). */
AK_API ak_grid_cell ak_grid_cell_of(const ak_grid* grid, ak_vec3 p);

/* Index m of a cell in the grid (its points are sorted entries [cell_start[m],
 * cell_start[m+1])), or UINT32_MAX when no point lies in it. */
AK_API uint32_t ak_grid_cell_find(const ak_grid* grid, ak_grid_cell cell);

/* Every original index j with |p_j - q| < radius (the module's distance test, strict <).
 * Writes min(total, out_indices.count) indices in grid order (cells around q in a fixed
 * order, then sorted order: deterministic for given points, desc, q and radius) and returns
 * the total, so a return above out_indices.count means the span was too short. radius not
 * > 0, NaN/infinite q or radius, or an empty grid -> 0. */
AK_API size_t ak_grid_query(const ak_grid* grid, ak_vec3 q, float radius, ak_u32_span out_indices);

/* Per-point neighbour lists in CSR form (the form SPH codes take): for every point i (original
 * index), the indices j != i with |p_j - p_i| < radius (the module's distance test, q = p_i),
 * at out_indices[out_offsets[i] .. out_offsets[i + 1]). Row i holds the same indices in the
 * same order as ak_grid_query(grid, p_i, radius) without i itself (cells around p_i in a fixed
 * order, then sorted order), so j is in row i exactly when i is in row j. */
typedef struct ak_grid_neighbors_job {
    const ak_grid* grid;      /* required */
    float radius;             /* required, > 0 and finite */
    uint32_t thread_count;    /* 0 -> 1; at most 64 */
    ak_u32_span out_offsets;  /* required, count >= point_count + 1 */
    ak_u32_span out_indices;  /* the lists; may be empty to count */
    size_t* out_index_count;  /* required: total entries (also when above capacity) */
    bool scalar_only;         /* use the scalar kernel even where AVX-512 is available (tests
                                 and benchmarks; the result is the same) */
} ak_grid_neighbors_job;

/* First failing rule: AK_ERR_NULL_ARG (job, grid, out_index_count or out_offsets.ptr NULL, or
 * out_indices.ptr NULL with count > 0), AK_ERR_BAD_ARG (radius not > 0 and finite,
 * thread_count > 64), AK_ERR_SPAN_SMALL (out_offsets shorter than point_count + 1). */
AK_API ak_result ak_grid_neighbors_validate(const ak_grid_neighbors_job* job);

/* Fills the neighbour lists: a counting pass writes out_offsets (always, when validation
 * passes), then, when out_indices has room for every entry, a second pass writes the lists.
 * Returns the validate codes, AK_OK, AK_ERR_SPAN_SMALL when out_indices.count is below the
 * total (*out_index_count says how many are needed; out_offsets is complete, out_indices
 * untouched), AK_ERR_BUDGET when the total reaches 2^32 - 1 (offsets are 32-bit). Output is
 * identical for any thread_count and on every CPU path. Never allocates. Cost: each point
 * tests the points of the 27 cells around it twice (count, then fill); use
 * 2 * ak_grid_candidate_count as the work estimate for untrusted input. */
AK_API ak_result ak_grid_neighbors_run(const ak_grid_neighbors_job* job);

/* The work a radius search over the whole grid does: the number of unordered point pairs
 * (i < j) that share a cell or lie in cells within reach of radius, i.e. the distance tests
 * ak_grid_pairs_run makes (the pairs it returns are a subset). Points spread at a density of
 * D per cell give about 13.5 D^2 per cell; N points in one cell give N (N - 1) / 2, the
 * quadratic cliff. Use it to check a work budget before a pass whose points come from
 * untrusted input. NULL, an empty grid or a radius not > 0 and finite -> 0. Cost: one visit
 * of the stencil per occupied cell, no distance test. */
AK_API uint64_t ak_grid_candidate_count(const ak_grid* grid, float radius);

/* All pairs closer than a radius. */
typedef struct ak_grid_pairs_job {
    const ak_grid* grid;         /* required */
    float radius;                /* required, > 0 and finite: pairs with |p_i - p_j| < radius */
    uint32_t thread_count;       /* 0 -> 1; at most 64 */
    ak_grid_pair_span out_pairs; /* pairs (i < j, original indices); may be empty to count */
    size_t* out_pair_count;      /* required: the number of pairs (also when above capacity) */
    bool scalar_only; /* use the scalar loops even where AVX-512 is available (tests and
                         benchmarks; the result is the same) */
} ak_grid_pairs_job;

/* First failing rule: AK_ERR_NULL_ARG (job, grid, out_pair_count, or out_pairs.ptr NULL with
 * count > 0), AK_ERR_BAD_ARG (radius not > 0 and finite, thread_count > 64). */
AK_API ak_result ak_grid_pairs_validate(const ak_grid_pairs_job* job);

/* Finds every pair i < j with |p_i - p_j| < radius, each once, exactly the brute-force set.
 * Order: by cell m of the grid, then neighbour cell, then sorted entries: deterministic, and
 * identical for any thread_count. Returns the validate codes, AK_OK, or AK_ERR_SPAN_SMALL
 * when out_pairs.count is below the number of pairs: *out_pair_count is then the number
 * needed and out_pairs holds an unspecified subset. Never allocates (threads keep their
 * state on the stack). */
AK_API ak_result ak_grid_pairs_run(const ak_grid_pairs_job* job);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_GRID_H */
