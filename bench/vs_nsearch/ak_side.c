/* animkit side of bench/vs_nsearch: grid build + all pairs, or grid build + CSR neighbour lists
 * (public API), memory allocated once and reused. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <animkit/grid.h>

static double wall(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int scalar_only = -1; /* AK_SCALAR=1 in the environment: the scalar loops */
static void* mem;
static size_t mem_bytes;
static ak_grid grid;
static ak_grid_pair* pairs;
static size_t pair_cap;
static uint32_t *offsets, *indices;
static size_t index_cap;

static void build(const float* p, size_t n, float r, double* t_build) {
    if (scalar_only < 0) scalar_only = getenv("AK_SCALAR") != NULL && getenv("AK_SCALAR")[0] == '1';
    ak_grid_desc gd = {.cell_size = r};
    size_t need = ak_grid_memory_size(n, &gd);
    if (need > mem_bytes) free(mem), mem = malloc(need), mem_bytes = need;
    double t0 = wall();
    ak_result rc = ak_grid_build(&gd, (ak_vec3_cspan){(const ak_vec3*)(const void*)p, n},
                                 (ak_u8_span){mem, mem_bytes}, &grid);
    *t_build = wall() - t0;
    if (rc != AK_OK) fprintf(stderr, "build %d\n", rc), exit(1);
}

/* build + all pairs; returns the pair count */
size_t ak_pairs_step(const float* p, size_t n, float r, unsigned threads, double* t_build, double* t_run) {
    build(p, n, r, t_build);
    size_t count = 0;
    double t0 = wall();
    for (;;) {
        ak_grid_pairs_job job = {.grid = &grid, .radius = r, .thread_count = threads,
                                 .out_pairs = {pairs, pair_cap}, .out_pair_count = &count,
                                 .scalar_only = scalar_only == 1};
        ak_result rc = ak_grid_pairs_run(&job);
        if (rc == AK_ERR_SPAN_SMALL) {
            free(pairs), pair_cap = count + count / 8, pairs = malloc(pair_cap * sizeof *pairs);
            t0 = wall();
            continue;
        }
        if (rc != AK_OK) fprintf(stderr, "pairs %d\n", rc), exit(1);
        break;
    }
    *t_run = wall() - t0;
    return count;
}

/* build + CSR lists; returns the entry count */
size_t ak_csr_step(const float* p, size_t n, float r, unsigned threads, double* t_build, double* t_run) {
    build(p, n, r, t_build);
    if (!offsets) offsets = malloc((n + 1) * sizeof *offsets);
    size_t count = 0;
    double t0 = wall();
    for (;;) {
        ak_grid_neighbors_job job = {.grid = &grid, .radius = r, .thread_count = threads,
                                     .out_offsets = {offsets, n + 1}, .out_indices = {indices, index_cap},
                                     .out_index_count = &count, .scalar_only = scalar_only == 1};
        ak_result rc = ak_grid_neighbors_run(&job);
        if (rc == AK_ERR_SPAN_SMALL) {
            free(indices), index_cap = count + count / 8, indices = malloc(index_cap * sizeof *indices);
            t0 = wall();
            continue;
        }
        if (rc != AK_OK) fprintf(stderr, "lists %d\n", rc), exit(1);
        break;
    }
    *t_run = wall() - t0;
    return count;
}

static unsigned long long mix(unsigned long long i, unsigned long long j) {
    unsigned long long x = (i << 32 | j) * 0x9E3779B97F4A7C15ull;
    return x ^ (x >> 29);
}
/* order-independent hashes of the last pair set (i < j) and of the last lists (every i, j) */
unsigned long long ak_pairs_hash(size_t count) {
    unsigned long long h = 0;
    for (size_t k = 0; k < count; ++k) h += mix(pairs[k].i, pairs[k].j);
    return h;
}
unsigned long long ak_csr_hash(size_t n) {
    unsigned long long h = 0;
    for (size_t i = 0; i < n; ++i)
        for (uint32_t k = offsets[i]; k < offsets[i + 1]; ++k) h += mix(i, indices[k]);
    return h;
}
void ak_free_all(void) {
    free(mem), free(pairs), free(offsets), free(indices);
    mem = NULL, pairs = NULL, offsets = indices = NULL, mem_bytes = pair_cap = index_cap = 0;
}
