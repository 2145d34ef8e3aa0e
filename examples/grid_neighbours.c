/* grid_neighbours: the uniform neighbour grid on 20,000 random points: all pairs closer than r
 * on one and two threads, checked against a brute-force count, one radius query, and every
 * point's neighbour list in CSR form (offsets + indices, as SPH codes take them). Prints
 * the counts and timings-free results (the grid needs no bounds and no allocation of its own). */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/grid.h>

int main(void) {
    enum { N = 20000 };
    const float r = 0.2f;
    ak_vec3* p = malloc(N * sizeof *p);
    if (!p) return 1;
    ak_rng rng = ak_rng_make(3);
    for (int i = 0; i < N; ++i)
        p[i] = ak_vec3_make(ak_rng_range(&rng, -3, 3), ak_rng_range(&rng, -3, 3),
                            ak_rng_range(&rng, -3, 3));
    p[0] = ak_vec3_make(1e7f, -1e7f, 0); /* far away: no bounds to declare */

    ak_grid_desc gd = {.cell_size = r};
    size_t bytes = ak_grid_memory_size(N, &gd);
    void* mem = malloc(bytes);
    ak_grid grid;
    if (!mem || ak_grid_build(&gd, (ak_vec3_cspan){p, N}, (ak_u8_span){mem, bytes}, &grid) != AK_OK)
        return 1;
    printf("%u points in %u occupied cells (%zu bytes of grid memory)\n", grid.point_count,
           grid.cell_count, bytes);

    size_t count = 0;
    ak_grid_pairs_job job = {.grid = &grid, .radius = r, .out_pair_count = &count};
    ak_grid_pairs_run(&job); /* an empty output span: just count */
    ak_grid_pair* pairs = malloc((count + 1) * sizeof *pairs);
    if (!pairs) return 1;
    job.out_pairs = (ak_grid_pair_span){pairs, count};
    job.thread_count = 2;
    if (ak_grid_pairs_run(&job) != AK_OK) return 1;

    size_t brute = 0;
    for (int i = 0; i < N; ++i)
        for (int j = i + 1; j < N; ++j) {
            float dx = p[j].x - p[i].x, dy = p[j].y - p[i].y, dz = p[j].z - p[i].z;
            brute += dx * dx + dy * dy + dz * dz < r * r;
        }
    printf("pairs closer than %.2f: grid %zu, brute force %zu%s\n", (double)r, count, brute,
           count == brute ? " (equal)" : " (DIFFERENT)");
    uint32_t near[64];
    size_t k = ak_grid_query(&grid, p[1], r, (ak_u32_span)AK_SPAN(near));
    printf("point 1 has %zu points within %.2f (itself included)\n", k, (double)r);

    /* CSR lists: a first run with no index span fills the offsets and says how many entries */
    uint32_t* offsets = malloc((N + 1) * sizeof *offsets);
    size_t entries = 0;
    ak_grid_neighbors_job nj = {.grid = &grid, .radius = r, .thread_count = 2,
                                .out_offsets = {offsets, N + 1}, .out_index_count = &entries};
    if (!offsets || ak_grid_neighbors_run(&nj) != (count ? AK_ERR_SPAN_SMALL : AK_OK)) return 1;
    uint32_t* lists = malloc((entries + 1) * sizeof *lists);
    nj.out_indices = (ak_u32_span){lists, entries};
    if (!lists || ak_grid_neighbors_run(&nj) != AK_OK) return 1;
    printf("neighbour lists: %zu entries (twice the pairs: %s); point 1 has %u neighbours\n", entries,
           entries == 2 * count ? "yes" : "NO", offsets[2] - offsets[1]);
    free(lists);
    free(offsets);
    free(pairs);
    free(mem);
    free(p);
    return count == brute && entries == 2 * count ? 0 : 1;
}
