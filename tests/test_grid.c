/* Tests for the neighbour grid: every query against a brute-force loop over all points. */
#include <animkit/grid.h>

#include "ak_test.h"

/* The module's distance test, written out independently. */
static int near_brute(ak_vec3 a, ak_vec3 b, float r) {
    float dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
    return dx * dx + dy * dy + dz * dz < r * r;
}

static int pair_cmp(const void* a, const void* b) {
    const ak_grid_pair *p = (const ak_grid_pair*)a, *q = (const ak_grid_pair*)b;
    if (p->i != q->i) return p->i < q->i ? -1 : 1;
    return p->j < q->j ? -1 : (p->j > q->j ? 1 : 0);
}

static int u32_cmp(const void* a, const void* b) {
    uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

static bool cell_eq(ak_grid_cell a, ak_grid_cell b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

typedef struct built {
    ak_grid grid;
    void* mem;
} built;

static built build(const ak_vec3* p, size_t n, float cell) {
    built b;
    ak_grid_desc d = {.cell_size = cell};
    size_t bytes = ak_grid_memory_size(n, &d);
    b.mem = malloc(bytes);
    ak_result r =
        ak_grid_build(&d, (ak_vec3_cspan){p, n}, (ak_u8_span){(uint8_t*)b.mem, bytes}, &b.grid);
    AK_CHECK_EQ(r, AK_OK);
    return b;
}

/* Builds the grid with cell size `cell` and checks pairs (on 1, 2 and 3 threads) and point
 * queries for radius r against brute force. Returns the number of pairs. */
static size_t check_cloud(const ak_vec3* p, size_t n, float cell, float r) {
    built b = build(p, n, cell);
    size_t brute = 0;
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) brute += (size_t)near_brute(p[i], p[j], r);
    ak_grid_pair* want = (ak_grid_pair*)malloc((brute + 1) * sizeof *want);
    size_t w = 0;
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j)
            if (near_brute(p[i], p[j], r)) want[w++] = (ak_grid_pair){(uint32_t)i, (uint32_t)j};

    ak_grid_pair* first = NULL;
    for (uint32_t run = 0; run < 4; ++run) { /* 1, 2, 3 threads, then the scalar loops */
        const uint32_t threads = run < 3 ? 1 + run : 1;
        ak_grid_pair* got = (ak_grid_pair*)malloc((brute + 1) * sizeof *got);
        size_t count = 0;
        ak_grid_pairs_job job = {.grid = &b.grid,
                                 .radius = r,
                                 .thread_count = threads,
                                 .out_pairs = {got, brute},
                                 .out_pair_count = &count,
                                 .scalar_only = run == 3};
        AK_CHECK_EQ(ak_grid_pairs_run(&job), AK_OK);
        AK_CHECK_EQ(count, brute);
        if (count == brute) {
            for (size_t k = 0; k < count; ++k) AK_CHECK(got[k].i < got[k].j);
            if (!first) {
                first = (ak_grid_pair*)malloc((brute + 1) * sizeof *first);
                memcpy(first, got, brute * sizeof *got);
            } else {
                /* Same pairs in the same order on any thread count and kernel. */
                AK_CHECK(memcmp(first, got, brute * sizeof *got) == 0);
            }
            qsort(got, count, sizeof *got, pair_cmp);
            AK_CHECK(brute == 0 || memcmp(got, want, brute * sizeof *got) == 0);
        }
        free(got);
    }
    free(first);

    /* Point queries at every 7th point and at points between them. */
    uint32_t* idx = (uint32_t*)malloc((n + 1) * sizeof *idx);
    for (size_t i = 0; i < n; i += 7) {
        ak_vec3 q = p[i];
        if (i % 2 && i + 1 < n) q = ak_vec3_scale(ak_vec3_add(p[i], p[i + 1]), 0.5f);
        size_t total = ak_grid_query(&b.grid, q, r, (ak_u32_span){idx, n});
        size_t expect = 0;
        for (size_t j = 0; j < n; ++j) expect += (size_t)near_brute(q, p[j], r);
        AK_CHECK_EQ(total, expect);
        if (total != expect) break;
        qsort(idx, total, sizeof *idx, u32_cmp);
        size_t k = 0;
        for (size_t j = 0; j < n; ++j)
            if (near_brute(q, p[j], r)) AK_CHECK_EQ(idx[k++], j);
    }
    free(idx);
    free(want);
    free(b.mem);
    return brute;
}

AK_TEST(random_cloud_matches_brute_force) {
    ak_rng rng = ak_rng_make(7);
    const size_t n = 3000;
    ak_vec3* p = (ak_vec3*)malloc(n * sizeof *p);
    for (size_t i = 0; i < n; ++i)
        p[i] = ak_vec3_make(ak_rng_range(&rng, -4, 4), ak_rng_range(&rng, -4, 4),
                            ak_rng_range(&rng, -4, 4));
    size_t pairs = check_cloud(p, n, 0.5f, 0.5f);
    AK_CHECK(pairs > 1000);         /* the cloud is dense enough to test something */
    check_cloud(p, n, 0.35f, 0.3f); /* r below the cell size */
    free(p);
}

AK_TEST(points_on_cell_boundaries) {
    /* A lattice with spacing = cell = r: every point sits on a cell corner and every axis
     * neighbour is at exactly r (excluded, strict <); diagonals are further. Then r a hair
     * above: the six axis neighbours count. */
    const float h = 0.25f;
    ak_vec3 p[6 * 6 * 6];
    size_t n = 0;
    for (int z = -3; z < 3; ++z)
        for (int y = -3; y < 3; ++y)
            for (int x = -3; x < 3; ++x) p[n++] = ak_vec3_make(x * h, y * h, z * h);
    AK_CHECK_EQ(check_cloud(p, n, h, h), 0);
    AK_CHECK_EQ(check_cloud(p, n, h, nextafterf(h, 1.0f)), 3 * 6 * 6 * 5);
    /* Half-cell lattice: points on boundaries and cell centres' faces. */
    AK_CHECK(check_cloud(p, n, 2 * h, 2 * h) > 0);
}

AK_TEST(points_far_outside_any_bounds) {
    ak_rng rng = ak_rng_make(11);
    ak_vec3 p[600];
    size_t n = 0;
    const float centres[5][3] = {
        {1e6f, 0, 0}, {-3e7f, 2e7f, 1e5f}, {4e9f, -4e9f, 4e9f}, {-1e30f, 1e30f, 0}, {0, 0, 0}};
    for (int c = 0; c < 5; ++c)
        for (int k = 0; k < 120; ++k) {
            float s = fabsf(centres[c][0]) > 1e8f ? 1e-7f * fabsf(centres[c][0])
                                                  : 1.0f; /* float spacing there */
            p[n++] = ak_vec3_make(centres[c][0] + s * ak_rng_range(&rng, -2, 2),
                                  centres[c][1] + s * ak_rng_range(&rng, -2, 2),
                                  centres[c][2] + s * ak_rng_range(&rng, -2, 2));
        }
    /* Small cells: far points clamp into shared cells but pairs stay exact. */
    AK_CHECK(check_cloud(p, n, 0.5f, 0.5f) > 0);
    check_cloud(p, n, 0.5f, 5e3f);
    built b = build(p, n, 0.5f); /* a box far too big for a dense table: the hash index */
    AK_CHECK(b.grid.dense == NULL && b.grid.bucket_count > 0);
    for (uint32_t m = 0; m < b.grid.cell_count; ++m) AK_CHECK_EQ(ak_grid_cell_find(&b.grid, b.grid.cell_coord[m]), m);
    free(b.mem);
}

AK_TEST(duplicates_and_large_radius) {
    ak_vec3 p[200];
    ak_rng rng = ak_rng_make(3);
    for (int i = 0; i < 200; ++i)
        p[i] = i < 50 ? ak_vec3_make(1, 2, 3)
                      : ak_vec3_make(ak_rng_range(&rng, 0, 4), ak_rng_range(&rng, 0, 4), 0);
    AK_CHECK(check_cloud(p, 200, 0.2f, 0.2f) >= 50 * 49 / 2);
    check_cloud(p, 200, 0.2f, 0.7f);                               /* r = 3.5 cells: four rings */
    check_cloud(p, 200, 0.2f, 1.0f);                               /* r = exactly 5 cells */
    AK_CHECK_EQ(check_cloud(p, 200, 0.2f, 100.0f), 200 * 199 / 2); /* all pairs: scans every cell */
}

AK_TEST(empty_and_single) {
    ak_vec3 p = {1, 1, 1};
    AK_CHECK_EQ(check_cloud(NULL, 0, 1.0f, 1.0f), 0);
    AK_CHECK_EQ(check_cloud(&p, 1, 1.0f, 1.0f), 0);
    built b = build(NULL, 0, 1.0f);
    uint32_t out[4];
    AK_CHECK_EQ(ak_grid_query(&b.grid, p, 1.0f, (ak_u32_span)AK_SPAN(out)), 0);
    AK_CHECK_EQ(b.grid.cell_count, 0);
    free(b.mem);
}

AK_TEST(sorted_layout_and_cells) {
    ak_rng rng = ak_rng_make(5);
    ak_vec3 p[500];
    for (int i = 0; i < 500; ++i)
        p[i] = ak_vec3_make(ak_rng_range(&rng, -2, 2), ak_rng_range(&rng, -2, 2),
                            ak_rng_range(&rng, -2, 2));
    built b = build(p, 500, 0.5f);
    const ak_grid* g = &b.grid;
    int seen[500] = {0};
    AK_CHECK_EQ(g->cell_start[0], 0);
    AK_CHECK_EQ(g->cell_start[g->cell_count], 500);
    for (uint32_t m = 0; m < g->cell_count; ++m) {
        AK_CHECK_EQ(ak_grid_cell_find(g, g->cell_coord[m]), m);
        for (uint32_t k = g->cell_start[m]; k < g->cell_start[m + 1]; ++k) {
            uint32_t i = g->order[k];
            seen[i]++;
            AK_CHECK(g->x[k] == p[i].x && g->y[k] == p[i].y && g->z[k] == p[i].z);
            /* floor(p / cell) computed independently */
            AK_CHECK_EQ(g->cell_coord[m].x, (int32_t)floor(p[i].x / 0.5));
            AK_CHECK_EQ(g->cell_coord[m].y, (int32_t)floor(p[i].y / 0.5));
            AK_CHECK_EQ(g->cell_coord[m].z, (int32_t)floor(p[i].z / 0.5));
            if (k > g->cell_start[m]) AK_CHECK(g->order[k - 1] < i); /* increasing inside a cell */
        }
    }
    for (int i = 0; i < 500; ++i) AK_CHECK_EQ(seen[i], 1);
    ak_grid_cell empty = {1000, 1000, 1000};
    AK_CHECK_EQ(ak_grid_cell_find(g, empty), UINT32_MAX);
    AK_CHECK(g->dense != NULL); /* 8^3 cells for 500 points: the dense table */
    for (int dz = -1; dz <= 8; ++dz) /* every cell of (and around) the box, against the points */
        for (int dy = -1; dy <= 8; ++dy)
            for (int dx = -1; dx <= 8; ++dx) {
                ak_grid_cell c = {dx - 4, dy - 4, dz - 4};
                bool any = false;
                for (int i = 0; i < 500; ++i)
                    any = any || ((int32_t)floor(p[i].x / 0.5) == c.x && (int32_t)floor(p[i].y / 0.5) == c.y &&
                                  (int32_t)floor(p[i].z / 0.5) == c.z);
                const uint32_t m = ak_grid_cell_find(g, c);
                AK_CHECK(any == (m != UINT32_MAX));
                if (m != UINT32_MAX) AK_CHECK(cell_eq(g->cell_coord[m], c));
            }
    ak_grid_cell c = ak_grid_cell_of(g, ak_vec3_make(-0.25f, 0.5f, 1.99f));
    AK_CHECK(c.x == -1 && c.y == 1 && c.z == 3);
    free(b.mem);
}

AK_TEST(short_output_reports_count) {
    ak_rng rng = ak_rng_make(9);
    ak_vec3 p[400];
    for (int i = 0; i < 400; ++i)
        p[i] = ak_vec3_make(ak_rng_range(&rng, 0, 3), ak_rng_range(&rng, 0, 3),
                            ak_rng_range(&rng, 0, 3));
    built b = build(p, 400, 0.5f);
    size_t brute = 0;
    for (int i = 0; i < 400; ++i)
        for (int j = i + 1; j < 400; ++j) brute += (size_t)near_brute(p[i], p[j], 0.5f);
    size_t count = 7;
    ak_grid_pairs_job job = {.grid = &b.grid, .radius = 0.5f, .out_pair_count = &count};
    AK_CHECK_EQ(ak_grid_pairs_run(&job), brute ? AK_ERR_SPAN_SMALL : AK_OK);
    AK_CHECK_EQ(count, brute);
    ak_grid_pair* got = (ak_grid_pair*)malloc(brute * sizeof *got);
    job.out_pairs = (ak_grid_pair_span){got, brute - 1};
    job.thread_count = 2;
    AK_CHECK_EQ(ak_grid_pairs_run(&job), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(count, brute);
    /* Exactly enough room; the threads' equal shares rarely match their counts, so this
     * usually takes the exact-offset second pass. */
    for (uint32_t t = 1; t <= 5; ++t) {
        job.out_pairs = (ak_grid_pair_span){got, brute};
        job.thread_count = t;
        AK_CHECK_EQ(ak_grid_pairs_run(&job), AK_OK);
        qsort(got, brute, sizeof *got, pair_cmp);
        size_t k = 0, bad = 0;
        for (uint32_t i = 0; i < 400; ++i)
            for (uint32_t j = i + 1; j < 400; ++j)
                if (near_brute(p[i], p[j], 0.5f)) bad += got[k].i != i || got[k].j != j, ++k;
        AK_CHECK_EQ(bad, 0);
    }
    uint32_t few[3];
    size_t total = ak_grid_query(&b.grid, p[0], 1.5f, (ak_u32_span)AK_SPAN(few));
    size_t expect = 0;
    for (int j = 0; j < 400; ++j) expect += (size_t)near_brute(p[0], p[j], 1.5f);
    AK_CHECK_EQ(total, expect);
    free(got);
    free(b.mem);
}

AK_TEST(validation_codes) {
    ak_vec3 p[2] = {{0, 0, 0}, {NAN, 0, 0}};
    uint8_t mem[4096];
    ak_grid g;
    ak_grid_desc d = {.cell_size = 1.0f};
    ak_grid_desc zero = {0};
    AK_CHECK(ak_grid_memory_size(2, &d) <= sizeof mem);
    AK_CHECK_EQ(ak_grid_memory_size(2, NULL), 0);
    AK_CHECK_EQ(ak_grid_build(NULL, (ak_vec3_cspan){p, 1}, (ak_u8_span)AK_SPAN(mem), &g),
                AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_grid_build(&d, (ak_vec3_cspan){NULL, 1}, (ak_u8_span)AK_SPAN(mem), &g),
                AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_grid_build(&zero, (ak_vec3_cspan){p, 1}, (ak_u8_span)AK_SPAN(mem), &g),
                AK_ERR_BAD_ARG);
    ak_grid_desc inf = {.cell_size = INFINITY};
    AK_CHECK_EQ(ak_grid_build(&inf, (ak_vec3_cspan){p, 1}, (ak_u8_span)AK_SPAN(mem), &g),
                AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_grid_build(&d, (ak_vec3_cspan){p, 1}, (ak_u8_span){mem, 8}, &g),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_grid_build(&d, (ak_vec3_cspan){p, 2}, (ak_u8_span)AK_SPAN(mem), &g),
                AK_ERR_BAD_DATA);
    AK_CHECK_EQ(g.point_count, 0);
    AK_CHECK_EQ(ak_grid_build(&d, (ak_vec3_cspan){p, 1}, (ak_u8_span){mem + 3, sizeof mem - 3}, &g),
                AK_OK);
    size_t count;
    ak_grid_pairs_job zj = {0};
    AK_CHECK_EQ(ak_grid_pairs_run(&zj), AK_ERR_NULL_ARG);
    ak_grid_pairs_job job = {.grid = &g, .radius = 1.0f, .out_pair_count = &count};
    AK_CHECK_EQ(ak_grid_pairs_validate(&job), AK_OK);
    job.out_pairs.count = 3;
    AK_CHECK_EQ(ak_grid_pairs_validate(&job), AK_ERR_NULL_ARG);
    job.out_pairs.count = 0;
    job.radius = 0.0f;
    AK_CHECK_EQ(ak_grid_pairs_validate(&job), AK_ERR_BAD_ARG);
    job.radius = NAN;
    AK_CHECK_EQ(ak_grid_pairs_validate(&job), AK_ERR_BAD_ARG);
    job.radius = 1.0f;
    job.thread_count = 65;
    AK_CHECK_EQ(ak_grid_pairs_validate(&job), AK_ERR_BAD_ARG);
    uint32_t out[2];
    AK_CHECK_EQ(ak_grid_query(&g, p[0], NAN, (ak_u32_span)AK_SPAN(out)), 0);
    AK_CHECK_EQ(ak_grid_query(&g, p[1], 1.0f, (ak_u32_span)AK_SPAN(out)), 0);
    AK_CHECK_EQ(ak_grid_query(&g, p[0], 1.0f, (ak_u32_span)AK_SPAN(out)), 1);
}

/* ak_grid_candidate_count against a brute-force count of the pairs whose cells (floor(p / cell)
 * in double, as the header says) are within k = ceil(r / cell) of each other on every axis. */
AK_TEST(candidate_count_matches_brute_force) {
    enum { N = 700 };
    ak_vec3 p[N];
    ak_rng rng = ak_rng_make(99);
    for (size_t i = 0; i < N; ++i) /* a clump, a sparse cloud and duplicates */
        p[i] = i < 200   ? ak_vec3_make(ak_rng_range(&rng, 0, 0.3f), ak_rng_range(&rng, 0, 0.3f), ak_rng_range(&rng, 0, 0.3f))
               : i < 650 ? ak_vec3_make(ak_rng_range(&rng, -5, 5), ak_rng_range(&rng, -5, 5), ak_rng_range(&rng, -5, 5))
                         : ak_vec3_make(2.0f, 2.0f, 2.0f);
    const float cells[] = {0.5f, 0.5f, 0.25f, 3.0f};
    const float radii[] = {0.5f, 1.2f, 0.5f, 0.1f};
    for (int c = 0; c < 4; ++c) {
        built b = build(p, N, cells[c]);
        double kd = ceil((double)radii[c] / (double)cells[c]);
        if (kd < 1.0) kd = 1.0;
        const int64_t k = (int64_t)kd;
        uint64_t want = 0;
        for (size_t i = 0; i < N; ++i)
            for (size_t j = i + 1; j < N; ++j) {
                bool in = true;
                const float a[3] = {p[i].x, p[i].y, p[i].z}, q[3] = {p[j].x, p[j].y, p[j].z};
                for (int ax = 0; ax < 3; ++ax) {
                    int64_t ca = (int64_t)floor((double)a[ax] / (double)cells[c]);
                    int64_t cb = (int64_t)floor((double)q[ax] / (double)cells[c]);
                    if (ca - cb > k || cb - ca > k) in = false;
                }
                want += in;
            }
        AK_CHECK_MSG(ak_grid_candidate_count(&b.grid, radii[c]) == want, "cell %g radius %g: %llu vs %llu",
                     (double)cells[c], (double)radii[c], (unsigned long long)ak_grid_candidate_count(&b.grid, radii[c]),
                     (unsigned long long)want);
        AK_CHECK_EQ(ak_grid_candidate_count(&b.grid, 0.0f), 0u);
        AK_CHECK_EQ(ak_grid_candidate_count(&b.grid, NAN), 0u);
        free(b.mem);
    }
    AK_CHECK_EQ(ak_grid_candidate_count(NULL, 1.0f), 0u);
    /* everything at one point: n (n - 1) / 2, the quadratic case a budget must catch */
    static ak_vec3 same[1000];
    for (size_t i = 0; i < 1000; ++i) same[i] = ak_vec3_make(1, 2, 3);
    built s = build(same, 1000, 0.1f);
    AK_CHECK_EQ(ak_grid_candidate_count(&s.grid, 0.1f), 1000u * 999u / 2u);
    free(s.mem);
}

/* ---- per-point neighbour lists (CSR) ---------------------------------------------------- */

/* The reference for row i: every j != i with |p_j - p_i| < r in double precision. A pair whose
 * double distance is within a relative 1e-5 of r may fall either way under the module's float
 * test; for those (and only those) the float test written out above decides. */
static bool near_ref(ak_vec3 a, ak_vec3 b, float r, int* ambiguous) {
    const double dx = (double)b.x - a.x, dy = (double)b.y - a.y, dz = (double)b.z - a.z;
    const double d2 = dx * dx + dy * dy + dz * dz, r2 = (double)r * r;
    if (d2 != r2 && fabs(d2 - r2) <= 1e-5 * r2) {
        ++*ambiguous;
        return near_brute(a, b, r);
    }
    return d2 < r2;
}

/* Builds with `cell`, runs the lists for radius r on 1, 2, 3 threads and the scalar kernel, checks
 * every row against the double reference (as a set), that all runs are bit-identical, and that
 * row i is ak_grid_query(p_i) without i. Returns the total entries. */
static size_t check_csr(const ak_vec3* p, size_t n, float cell, float r) {
    built b = build(p, n, cell);
    uint32_t* ref_off = (uint32_t*)calloc(n + 1, sizeof *ref_off);
    size_t ref_total = 0;
    int ambiguous = 0;
    for (size_t i = 0; i < n; ++i) {
        for (size_t j = 0; j < n; ++j) ref_total += j != i && near_ref(p[i], p[j], r, &ambiguous);
        ref_off[i + 1] = (uint32_t)ref_total;
    }
    uint32_t* ref = (uint32_t*)malloc((ref_total + 1) * sizeof *ref);
    for (size_t i = 0, w = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j)
            if (j != i && near_ref(p[i], p[j], r, &ambiguous)) ref[w++] = (uint32_t)j;
    AK_CHECK(ambiguous < 1 + (int)n / 10); /* the boundary cases stay rare */

    uint32_t* first_off = NULL;
    uint32_t* first = NULL;
    uint32_t* off = (uint32_t*)malloc((n + 1) * sizeof *off);
    uint32_t* idx = (uint32_t*)malloc((ref_total + 1) * sizeof *idx);
    uint32_t* row = (uint32_t*)malloc((n + 1) * sizeof *row);
    for (int scalar = 0; scalar <= 1; ++scalar) /* 1, 2, 3 threads, then the scalar kernel */
        for (uint32_t threads = 1; threads <= (scalar ? 1u : 3u); ++threads) {
            size_t total = 0;
            memset(idx, 0xAB, (ref_total + 1) * sizeof *idx);
            ak_grid_neighbors_job job = {.grid = &b.grid, .radius = r, .thread_count = threads,
                                         .out_offsets = {off, n + 1}, .out_indices = {idx, ref_total},
                                         .out_index_count = &total, .scalar_only = scalar != 0};
            AK_CHECK_EQ(ak_grid_neighbors_run(&job), AK_OK);
            AK_CHECK_EQ(total, ref_total);
            if (total != ref_total) continue;
            if (!first) {
                first = (uint32_t*)malloc((ref_total + 1) * sizeof *first);
                first_off = (uint32_t*)malloc((n + 1) * sizeof *first_off);
                memcpy(first, idx, ref_total * sizeof *idx);
                memcpy(first_off, off, (n + 1) * sizeof *off);
                size_t bad = 0, bad_query = 0;
                for (size_t i = 0; i < n; ++i) {
                    const uint32_t k = off[i + 1] - off[i];
                    bad += k != ref_off[i + 1] - ref_off[i];
                    if (k != ref_off[i + 1] - ref_off[i]) continue;
                    memcpy(row, idx + off[i], k * sizeof *row);
                    qsort(row, k, sizeof *row, u32_cmp);
                    bad += memcmp(row, ref + ref_off[i], k * sizeof *row) != 0;
                    /* the order of ak_grid_query, i left out */
                    size_t q = ak_grid_query(&b.grid, p[i], r, (ak_u32_span){row, n + 1}), w = 0;
                    bad_query += q != k + 1;
                    for (size_t e = 0; e < q && e <= n && w < k; ++e)
                        if (row[e] != i) bad_query += row[e] != idx[off[i] + w++];
                }
                AK_CHECK_EQ(bad, 0);
                AK_CHECK_EQ(bad_query, 0);
            } else {
                AK_CHECK(memcmp(first_off, off, (n + 1) * sizeof *off) == 0);
                AK_CHECK(ref_total == 0 || memcmp(first, idx, ref_total * sizeof *idx) == 0);
            }
        }
    free(first);
    free(first_off);
    free(off);
    free(idx);
    free(row);
    free(ref);
    free(ref_off);
    free(b.mem);
    return ref_total;
}

AK_TEST(csr_random_and_clustered) {
    enum { N = 700 };
    static ak_vec3 p[N];
    ak_rng rng = ak_rng_make(321);
    for (size_t i = 0; i < N; ++i) /* a uniform cloud, a tight clump, duplicates */
        p[i] = i < 450    ? ak_vec3_make(ak_rng_range(&rng, -3, 3), ak_rng_range(&rng, -3, 3), ak_rng_range(&rng, -3, 3))
               : i < 650  ? ak_vec3_make(ak_rng_range(&rng, 1, 1.4f), ak_rng_range(&rng, 1, 1.4f), ak_rng_range(&rng, 1, 1.4f))
                          : p[i - 300];
    AK_CHECK(check_csr(p, N, 0.5f, 0.5f) > 2000);  /* cell = radius: the 27-cell block */
    AK_CHECK(check_csr(p, N, 0.25f, 0.5f) > 2000); /* radius 2 cells: 125 cells, in chunks */
    AK_CHECK(check_csr(p, N, 2.0f, 0.5f) > 2000);  /* big cells */
    AK_CHECK(check_csr(p, N, 0.5f, 40.0f) == (size_t)N * (N - 1)); /* all cells scanned */
}

/* Points exactly one radius apart are not neighbours (strict <); a hair closer they are. */
AK_TEST(csr_points_at_the_radius) {
    ak_vec3 p[6 * 6 * 6];
    size_t n = 0;
    for (int z = 0; z < 6; ++z)
        for (int y = 0; y < 6; ++y)
            for (int x = 0; x < 6; ++x) p[n++] = ak_vec3_make(0.5f * x, 0.5f * y, 0.5f * z);
    /* spacing 0.5 = radius: no axis neighbour, only... nothing closer than 0.5 either */
    AK_CHECK_EQ(check_csr(p, n, 0.5f, 0.5f), 0);
    /* radius just above 0.5: the 6 axis neighbours of each interior point (not the diagonals,
     * 0.707 away): 3 axes x 2 directions x 5 x 6 x 6 links */
    AK_CHECK_EQ(check_csr(p, n, 0.5f, 0.50001f), 3 * 2 * 5 * 6 * 6);
    AK_CHECK_EQ(check_csr(p, n, 0.37f, 0.50001f), 3 * 2 * 5 * 6 * 6);
}

AK_TEST(csr_one_cell_empty_and_errors) {
    ak_vec3 same[40];
    for (int i = 0; i < 40; ++i) same[i] = ak_vec3_make(0.1f + 0.001f * (float)(i % 4), 0.2f, 0.3f);
    AK_CHECK_EQ(check_csr(same, 40, 1.0f, 0.5f), 40 * 39); /* one cell, every point near */
    AK_CHECK_EQ(check_csr(same, 0, 1.0f, 0.5f), 0);
    AK_CHECK_EQ(check_csr(same, 1, 1.0f, 0.5f), 0);

    built b = build(same, 40, 1.0f);
    uint32_t off[41], idx[8];
    size_t total = 99;
    ak_grid_neighbors_job job = {.grid = &b.grid, .radius = 0.5f, .out_offsets = {off, 41},
                                 .out_indices = {idx, 8}, .out_index_count = &total};
    /* too short: the count and complete offsets come back, the lists stay untouched */
    memset(idx, 0xCD, sizeof idx);
    AK_CHECK_EQ(ak_grid_neighbors_run(&job), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(total, 40u * 39u);
    AK_CHECK_EQ(off[0], 0);
    for (int i = 0; i < 40; ++i) AK_CHECK_EQ(off[i + 1] - off[i], 39u);
    AK_CHECK_EQ(idx[0], 0xCDCDCDCDu);
    job.out_offsets.count = 40;
    AK_CHECK_EQ(ak_grid_neighbors_run(&job), AK_ERR_SPAN_SMALL);
    job.out_offsets.count = 41;
    job.radius = NAN;
    AK_CHECK_EQ(ak_grid_neighbors_run(&job), AK_ERR_BAD_ARG);
    job.radius = -1.0f;
    AK_CHECK_EQ(ak_grid_neighbors_validate(&job), AK_ERR_BAD_ARG);
    job.radius = 0.5f;
    job.thread_count = 65;
    AK_CHECK_EQ(ak_grid_neighbors_validate(&job), AK_ERR_BAD_ARG);
    job.thread_count = 0;
    job.out_index_count = NULL;
    AK_CHECK_EQ(ak_grid_neighbors_validate(&job), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_grid_neighbors_validate(NULL), AK_ERR_NULL_ARG);
    free(b.mem);

    /* NaN positions never reach the lists: the build refuses them */
    ak_vec3 bad[3] = {{0, 0, 0}, {1, NAN, 0}, {0, 0, 1}};
    ak_grid_desc d = {.cell_size = 1.0f};
    uint8_t mem[4096];
    ak_grid g;
    AK_CHECK(ak_grid_memory_size(3, &d) <= sizeof mem);
    AK_CHECK_EQ(ak_grid_build(&d, (ak_vec3_cspan){bad, 3}, (ak_u8_span)AK_SPAN(mem), &g), AK_ERR_BAD_DATA);
    job.grid = &g; /* the empty grid a failed build leaves */
    job.out_index_count = &total;
    AK_CHECK_EQ(ak_grid_neighbors_run(&job), AK_OK);
    AK_CHECK_EQ(total, 0);
    AK_CHECK_EQ(off[0], 0);
}

/* Morton order: the z-curve code of (cell - lowest cell), computed bit by bit here, increases
 * with m; the hash order lists the same cells; an unknown order is refused. */
AK_TEST(cell_orders) {
    ak_rng rng = ak_rng_make(17);
    ak_vec3 p[600];
    for (int i = 0; i < 600; ++i)
        p[i] = ak_vec3_make(ak_rng_range(&rng, -3, 5), ak_rng_range(&rng, -2, 2), ak_rng_range(&rng, 0, 9));
    built b = build(p, 600, 0.5f);
    const ak_grid* g = &b.grid;
    int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX};
    for (uint32_t m = 0; m < g->cell_count; ++m) {
        const int32_t c[3] = {g->cell_coord[m].x, g->cell_coord[m].y, g->cell_coord[m].z};
        for (int a = 0; a < 3; ++a) lo[a] = c[a] < lo[a] ? c[a] : lo[a];
    }
    uint64_t prev = 0;
    for (uint32_t m = 0; m < g->cell_count; ++m) {
        const uint64_t o[3] = {(uint64_t)(g->cell_coord[m].x - lo[0]), (uint64_t)(g->cell_coord[m].y - lo[1]),
                               (uint64_t)(g->cell_coord[m].z - lo[2])};
        uint64_t code = 0;
        for (int bit = 0; bit < 21; ++bit)
            for (int a = 0; a < 3; ++a) code |= ((o[a] >> bit) & 1u) << (3 * bit + a);
        if (m > 0) AK_CHECK(code > prev);
        prev = code;
    }
    ak_grid_desc hd = {.cell_size = 0.5f, .cell_order = AK_GRID_ORDER_HASH};
    size_t bytes = ak_grid_memory_size(600, &hd);
    void* mem = malloc(bytes);
    ak_grid h;
    AK_CHECK_EQ(ak_grid_build(&hd, (ak_vec3_cspan){p, 600}, (ak_u8_span){(uint8_t*)mem, bytes}, &h), AK_OK);
    AK_CHECK_EQ(h.cell_count, g->cell_count);
    size_t moved = 0;
    for (uint32_t m = 0; m < h.cell_count; ++m) {
        const uint32_t o = ak_grid_cell_find(g, h.cell_coord[m]);
        AK_CHECK(o != UINT32_MAX);
        if (o == UINT32_MAX) continue;
        moved += o != m;
        AK_CHECK_EQ(h.cell_start[m + 1] - h.cell_start[m], g->cell_start[o + 1] - g->cell_start[o]);
    }
    AK_CHECK(moved > 0); /* a different order of the same cells */
    hd.cell_order = (ak_grid_cell_order)7;
    AK_CHECK_EQ(ak_grid_build(&hd, (ak_vec3_cspan){p, 600}, (ak_u8_span){(uint8_t*)mem, bytes}, &h), AK_ERR_BAD_ARG);
    free(mem);
    free(b.mem);
}

int main(void) {
    AK_RUN(random_cloud_matches_brute_force);
    AK_RUN(points_on_cell_boundaries);
    AK_RUN(points_far_outside_any_bounds);
    AK_RUN(duplicates_and_large_radius);
    AK_RUN(empty_and_single);
    AK_RUN(sorted_layout_and_cells);
    AK_RUN(short_output_reports_count);
    AK_RUN(validation_codes);
    AK_RUN(candidate_count_matches_brute_force);
    AK_RUN(cell_orders);
    AK_RUN(csr_random_and_clustered);
    AK_RUN(csr_points_at_the_radius);
    AK_RUN(csr_one_cell_empty_and_errors);
    return ak_test_finish();
}
