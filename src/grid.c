/* Uniform-grid neighbour search: hashed cell keys, counting sort, exact radius queries. */
#include <animkit/grid.h>

#include <math.h>

#include "tasks.h"
#include "internal.h"
#include "grid/grid_internal.h"

#define GRID_COORD_LIMIT 1073741824.0 /* 2^30: clamp for cell coordinates */
#define GRID_MAX_THREADS 64u

/* ---- helpers ------------------------------------------------------------------------ */

static inline int32_t cell_coord(float p, double inv_cell) {
    double v = floor((double)p * inv_cell);
    if (!(v >= -GRID_COORD_LIMIT)) v = -GRID_COORD_LIMIT; /* NaN too */
    if (v > GRID_COORD_LIMIT) v = GRID_COORD_LIMIT;
    return (int32_t)v;
}

static inline ak_grid_cell cell_of(float x, float y, float z, double inv_cell) {
    ak_grid_cell c = {cell_coord(x, inv_cell), cell_coord(y, inv_cell), cell_coord(z, inv_cell)};
    return c;
}

static inline uint32_t cell_hash(ak_grid_cell c) {
    uint32_t h =
        (uint32_t)c.x * 0x9E3779B1u ^ (uint32_t)c.y * 0x85EBCA77u ^ (uint32_t)c.z * 0xC2B2AE3Du;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    return h;
}

static inline bool cell_eq(ak_grid_cell a, ak_grid_cell b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

static inline bool cell_less(ak_grid_cell a, ak_grid_cell b) {
    if (a.z != b.z) return a.z < b.z;
    if (a.y != b.y) return a.y < b.y;
    return a.x < b.x;
}

static size_t bucket_count_for(size_t n) {
    size_t b = 16;
    while (b < 2 * n && b < ((size_t)1 << 31)) b <<= 1;
    return b;
}

/* Carves the caller's memory; the same walk sizes it (base NULL). */
typedef struct layout {
    uint32_t* order;
    float *x, *y, *z;
    uint32_t* cell_start;
    ak_grid_cell* cell_coord;
    uint32_t* bucket_start;
    ak_grid_bucket_entry* bucket_entry;
    uint64_t* key; /* temporaries from here on */
    uint64_t* key_tmp;
    uint32_t* idx_tmp;
    ak_grid_cell* point_cell;
} layout;

/* The grid's arrays from the carved layout: the same for the dense table (no buckets, no
 * bucket entries: the table lives in their place) and the hash index. */
static void publish(ak_grid* g, const layout* l, size_t n, uint32_t cells, size_t buckets,
                    ak_grid_bucket_entry* bucket_entry) {
    g->point_count = (uint32_t)n;
    g->cell_count = cells;
    g->bucket_count = (uint32_t)buckets;
    g->order = l->order;
    g->x = l->x;
    g->y = l->y;
    g->z = l->z;
    g->cell_start = l->cell_start;
    g->cell_coord = l->cell_coord;
    g->bucket_start = l->bucket_start;
    g->bucket_entry = bucket_entry;
}

static size_t carve(uint8_t* base, size_t n, size_t buckets, layout* l) {
    size_t off = 0;
#define GRID_TAKE(field, type, count)                                                              \
    do {                                                                                           \
        l->field = base ? (type*)(void*)(base + off) : NULL;                                       \
        off += akp_align16(sizeof(type) * (count));                                                \
    } while (0)
    GRID_TAKE(order, uint32_t, n);
    GRID_TAKE(x, float, n);
    GRID_TAKE(y, float, n);
    GRID_TAKE(z, float, n);
    GRID_TAKE(cell_start, uint32_t, n + 1);
    GRID_TAKE(cell_coord, ak_grid_cell, n);
    GRID_TAKE(bucket_start, uint32_t, buckets + 1);
    GRID_TAKE(bucket_entry, ak_grid_bucket_entry, n);
    GRID_TAKE(key, uint64_t, n);
    GRID_TAKE(key_tmp, uint64_t, n);
    GRID_TAKE(idx_tmp, uint32_t, n);
    GRID_TAKE(point_cell, ak_grid_cell, n);
#undef GRID_TAKE
    return off;
}

/* Stable bottom-up merge sort of idx[0..n) by the cells of the points. */
static void sort_by_cell(uint32_t* idx, uint32_t* tmp, size_t n, const ak_grid_cell* pc) {
    uint32_t *src = idx, *dst = tmp;
    for (size_t w = 1; w < n; w *= 2) {
        for (size_t lo = 0; lo < n; lo += 2 * w) {
            size_t mid = lo + w < n ? lo + w : n, hi = lo + 2 * w < n ? lo + 2 * w : n;
            size_t a = lo, b = mid, o = lo;
            while (a < mid && b < hi)
                dst[o++] = cell_less(pc[src[b]], pc[src[a]]) ? src[b++] : src[a++];
            while (a < mid) dst[o++] = src[a++];
            while (b < hi) dst[o++] = src[b++];
        }
        uint32_t* t = src;
        src = dst;
        dst = t;
    }
    if (src != idx) memcpy(idx, src, n * sizeof *idx);
}

/* The low 21 bits of v spread to every third bit (bit i -> bit 3i). */
static inline uint64_t spread21(uint64_t v) {
    v &= 0x1FFFFFu;
    v = (v | v << 32) & 0x001F00000000FFFFull;
    v = (v | v << 16) & 0x001F0000FF0000FFull;
    v = (v | v << 8) & 0x100F00F00F00F00Full;
    v = (v | v << 4) & 0x10C30C30C30C30C3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

/* Stable LSD radix sort of (key, idx)[0..n) on the low `bits` bits of key, 11 bits a pass
 * (digits every key shares are skipped). The result ends in key/idx. */
static void radix_sort(uint64_t* key, uint32_t* idx, uint64_t* key_tmp, uint32_t* idx_tmp, size_t n,
                       unsigned bits) {
    enum { DIGIT = 11, BINS = 1 << DIGIT };
    uint64_t *ks = key, *kd = key_tmp;
    uint32_t *is = idx, *id = idx_tmp;
    uint32_t count[BINS];
    for (unsigned shift = 0; shift < bits; shift += DIGIT) {
        memset(count, 0, sizeof count);
        for (size_t i = 0; i < n; ++i) count[(ks[i] >> shift) & (BINS - 1)]++;
        if (count[(ks[0] >> shift) & (BINS - 1)] == n) continue; /* one digit for all */
        uint32_t sum = 0;
        for (unsigned b = 0; b < BINS; ++b) {
            uint32_t c = count[b];
            count[b] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; ++i) {
            const uint32_t o = count[(ks[i] >> shift) & (BINS - 1)]++;
            kd[o] = ks[i];
            id[o] = is[i];
        }
        uint64_t* kt = ks;
        ks = kd;
        kd = kt;
        uint32_t* it = is;
        is = id;
        id = it;
    }
    if (ks != key) {
        memcpy(key, ks, n * sizeof *key);
        memcpy(idx, is, n * sizeof *idx);
    }
}

/* Rings of cells a radius needs: the smallest k with k * cell_size >= radius. */
static int64_t rings_for(const ak_grid* g, float radius) {
    double k = ceil((double)radius / (double)g->cell_size);
    if (k < 1.0) k = 1.0;
    if (k * (double)g->cell_size < (double)radius) k += 1.0;
    if (k > 4096.0) k = 4096.0; /* beyond this every query scans all cells anyway */
    return (int64_t)k;
}

/* True when visiting a (2k+1)^3 stencil costs more than scanning every cell. */
static bool scan_all_cells(const ak_grid* g, int64_t k) {
    int64_t side = 2 * k + 1;
    return side * side * side > (int64_t)g->cell_count + 27;
}

static inline int64_t abs64(int64_t v) { return v < 0 ? -v : v; }

static inline bool cells_within(ak_grid_cell a, ak_grid_cell b, int64_t k) {
    return abs64((int64_t)a.x - b.x) <= k && abs64((int64_t)a.y - b.y) <= k &&
           abs64((int64_t)a.z - b.z) <= k;
}

static inline bool coord_offset_ok(int32_t c, int64_t d) {
    int64_t v = (int64_t)c + d;
    return v >= -(int64_t)GRID_COORD_LIMIT && v <= (int64_t)GRID_COORD_LIMIT;
}

/* ---- public: build ------------------------------------------------------------------ */

size_t ak_grid_memory_size(size_t point_count, const ak_grid_desc* desc) {
    if (!desc || point_count >= ((size_t)1 << 31)) return 0;
    layout l;
    return carve(NULL, point_count, bucket_count_for(point_count), &l) + 16;
}

ak_result ak_grid_build(const ak_grid_desc* desc, ak_vec3_cspan points, ak_u8_span memory,
                        ak_grid* out_grid) {
    if (out_grid) memset(out_grid, 0, sizeof *out_grid);
    if (!desc || !out_grid || !memory.ptr || (!points.ptr && points.count > 0))
        return AK_ERR_NULL_ARG;
    if (!(desc->cell_size > 0.0f) || !ak_finitef(desc->cell_size) ||
        points.count >= ((size_t)1 << 31) ||
        (desc->cell_order != AK_GRID_ORDER_MORTON && desc->cell_order != AK_GRID_ORDER_HASH))
        return AK_ERR_BAD_ARG;
    const size_t n = points.count;
    if (memory.count < ak_grid_memory_size(n, desc)) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i) {
        const ak_vec3 p = points.ptr[i];
        if (!ak_finitef(p.x) || !ak_finitef(p.y) || !ak_finitef(p.z)) return AK_ERR_BAD_DATA;
    }
    uint8_t* base = memory.ptr + ((16u - ((uintptr_t)memory.ptr & 15u)) & 15u);
    layout l;
    carve(base, n, bucket_count_for(n), &l);
    out_grid->cell_size = desc->cell_size;

    /* Cell of every point and the box of occupied cells. */
    const double inv = 1.0 / (double)desc->cell_size;
    int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    for (size_t i = 0; i < n; ++i) {
        const ak_vec3 p = points.ptr[i];
        const ak_grid_cell c = cell_of(p.x, p.y, p.z, inv);
        l.point_cell[i] = c;
        lo[0] = c.x < lo[0] ? c.x : lo[0], hi[0] = c.x > hi[0] ? c.x : hi[0];
        lo[1] = c.y < lo[1] ? c.y : lo[1], hi[1] = c.y > hi[1] ? c.y : hi[1];
        lo[2] = c.z < lo[2] ? c.z : lo[2], hi[2] = c.z > hi[2] ? c.z : hi[2];
    }
    /* Morton code of (cell - lowest cell); beyond 2^21 cells on an axis, of the offsets shifted
     * right until they fit (cells sharing a code are then ordered by cell_less below). */
    unsigned bits = 0, shift = 0;
    for (int a = 0; a < 3 && n > 0; ++a) {
        const uint64_t ext = (uint64_t)((int64_t)hi[a] - lo[a]);
        unsigned b = 0;
        while (b < 40 && (ext >> b) != 0) ++b;
        bits = b > bits ? b : bits;
    }
    if (bits > 21) shift = bits - 21, bits = 21;
    unsigned key_bits = 3 * bits;
    bool ties = shift > 0; /* cells may share a key */
    if (desc->cell_order == AK_GRID_ORDER_HASH) { /* key = hash bucket (the table of n points) */
        const size_t hb = bucket_count_for(n);
        key_bits = 0;
        while (((size_t)1 << key_bits) < hb) ++key_bits;
        ties = true;
        for (size_t i = 0; i < n; ++i) {
            l.key[i] = cell_hash(l.point_cell[i]) & (uint32_t)(hb - 1);
            l.order[i] = (uint32_t)i;
        }
    } else {
        for (size_t i = 0; i < n; ++i) {
            const ak_grid_cell c = l.point_cell[i];
            const uint64_t ox = (uint64_t)((int64_t)c.x - lo[0]) >> shift;
            const uint64_t oy = (uint64_t)((int64_t)c.y - lo[1]) >> shift;
            const uint64_t oz = (uint64_t)((int64_t)c.z - lo[2]) >> shift;
            l.key[i] = spread21(ox) | spread21(oy) << 1 | spread21(oz) << 2;
            l.order[i] = (uint32_t)i;
        }
    }
    /* Stable: the points of a cell keep increasing original index. */
    if (n > 0) radix_sort(l.key, l.order, l.key_tmp, l.idx_tmp, n, key_bits);
    if (ties) {
        size_t start = 0;
        for (size_t k = 1; k <= n; ++k) {
            if (k < n && l.key[k] == l.key[start]) continue;
            if (k - start > 1) sort_by_cell(l.order + start, l.idx_tmp, k - start, l.point_cell);
            start = k;
        }
    }

    /* Cells in that order and positions in sorted order. */
    uint32_t cells = 0;
    for (size_t k = 0; k < n; ++k) {
        const uint32_t i = l.order[k];
        if (k == 0 || !cell_eq(l.point_cell[i], l.cell_coord[cells - 1])) {
            l.cell_start[cells] = (uint32_t)k;
            l.cell_coord[cells] = l.point_cell[i];
            ++cells;
        }
        l.x[k] = points.ptr[i].x;
        l.y[k] = points.ptr[i].y;
        l.z[k] = points.ptr[i].z;
    }
    l.cell_start[cells] = (uint32_t)n;

    /* A dense table over the box of occupied cells when it has at most 4 cells per point: it
     * lives where the hash index would (bucket_entry: 16 bytes = 4 slots per point). */
    const uint64_t dim[3] = {n ? (uint64_t)((int64_t)hi[0] - lo[0]) + 1 : 0,
                             n ? (uint64_t)((int64_t)hi[1] - lo[1]) + 1 : 0,
                             n ? (uint64_t)((int64_t)hi[2] - lo[2]) + 1 : 0};
    if (n > 0 && dim[0] <= 4 * (uint64_t)n && dim[1] <= 4 * (uint64_t)n && dim[2] <= 4 * (uint64_t)n &&
        dim[0] * dim[1] <= 4 * (uint64_t)n && dim[0] * dim[1] * dim[2] <= 4 * (uint64_t)n) {
        uint32_t* table = (uint32_t*)(void*)l.bucket_entry;
        const size_t vol = (size_t)(dim[0] * dim[1] * dim[2]);
        memset(table, 0xFF, vol * sizeof *table);
        for (uint32_t m = 0; m < cells; ++m) {
            const ak_grid_cell c = l.cell_coord[m];
            table[((size_t)((int64_t)c.z - lo[2]) * dim[1] + (size_t)((int64_t)c.y - lo[1])) * dim[0] +
                  (size_t)((int64_t)c.x - lo[0])] = m;
        }
        l.bucket_start[0] = 0;
        out_grid->dense = table;
        out_grid->dense_origin = (ak_grid_cell){lo[0], lo[1], lo[2]};
        for (int a = 0; a < 3; ++a) out_grid->dense_dim[a] = (uint32_t)dim[a];
        publish(out_grid, &l, n, cells, 0, NULL);
        return AK_OK;
    }

    /* The hash index: cells of bucket b (increasing m) at bucket_entry[bucket_start[b] ..). */
    const size_t buckets = bucket_count_for(cells);
    const uint32_t mask = (uint32_t)(buckets - 1);
    memset(l.bucket_start, 0, (buckets + 1) * sizeof(uint32_t));
    for (uint32_t m = 0; m < cells; ++m) l.bucket_start[cell_hash(l.cell_coord[m]) & mask]++;
    for (size_t b = 1; b < buckets; ++b) l.bucket_start[b] += l.bucket_start[b - 1];
    l.bucket_start[buckets] = cells; /* bucket_start[b] is now the end of bucket b */
    for (uint32_t m = cells; m-- > 0;) {
        const uint32_t b = cell_hash(l.cell_coord[m]) & mask;
        l.bucket_entry[--l.bucket_start[b]] = (ak_grid_bucket_entry){l.cell_coord[m], m};
    }

    publish(out_grid, &l, n, cells, buckets, l.bucket_entry);
    return AK_OK;
}

/* ---- public: cells and point queries ------------------------------------------------ */

ak_grid_cell ak_grid_cell_of(const ak_grid* grid, ak_vec3 p) {
    ak_grid_cell zero = {0, 0, 0};
    if (!grid || !(grid->cell_size > 0.0f)) return zero;
    return cell_of(p.x, p.y, p.z, 1.0 / (double)grid->cell_size);
}

uint32_t ak_grid_cell_find(const ak_grid* grid, ak_grid_cell cell) {
    if (!grid || grid->cell_count == 0) return UINT32_MAX;
    if (grid->dense) {
        const uint64_t x = (uint64_t)((int64_t)cell.x - grid->dense_origin.x);
        const uint64_t y = (uint64_t)((int64_t)cell.y - grid->dense_origin.y);
        const uint64_t z = (uint64_t)((int64_t)cell.z - grid->dense_origin.z);
        if (x >= grid->dense_dim[0] || y >= grid->dense_dim[1] || z >= grid->dense_dim[2])
            return UINT32_MAX;
        return grid->dense[(z * grid->dense_dim[1] + y) * grid->dense_dim[0] + x];
    }
    const uint32_t b = cell_hash(cell) & (grid->bucket_count - 1);
    for (uint32_t e = grid->bucket_start[b]; e < grid->bucket_start[b + 1]; ++e)
        if (cell_eq(grid->bucket_entry[e].cell, cell)) return grid->bucket_entry[e].index;
    return UINT32_MAX;
}

/* Points of cell m within radius of q (the module's distance test); returns the new total. */
static size_t query_cell(const ak_grid* g, uint32_t m, float qx, float qy, float qz, float r2,
                         ak_u32_span out, size_t total) {
    for (uint32_t k = g->cell_start[m]; k < g->cell_start[m + 1]; ++k) {
        const float dx = g->x[k] - qx, dy = g->y[k] - qy, dz = g->z[k] - qz;
        if (dx * dx + dy * dy + dz * dz < r2) {
            if (total < out.count) out.ptr[total] = g->order[k];
            ++total;
        }
    }
    return total;
}

size_t ak_grid_query(const ak_grid* grid, ak_vec3 q, float radius, ak_u32_span out_indices) {
    if (!grid || grid->point_count == 0 || !(radius > 0.0f) || !ak_finitef(radius) ||
        !ak_finitef(q.x) || !ak_finitef(q.y) || !ak_finitef(q.z))
        return 0;
    if (!out_indices.ptr) out_indices.count = 0;
    const float r2 = radius * radius;
    const int64_t k = rings_for(grid, radius);
    const ak_grid_cell c = ak_grid_cell_of(grid, q);
    size_t total = 0;
    if (scan_all_cells(grid, k)) {
        for (uint32_t m = 0; m < grid->cell_count; ++m)
            if (cells_within(grid->cell_coord[m], c, k))
                total = query_cell(grid, m, q.x, q.y, q.z, r2, out_indices, total);
        return total;
    }
    for (int64_t dz = -k; dz <= k; ++dz) {
        if (!coord_offset_ok(c.z, dz)) continue;
        for (int64_t dy = -k; dy <= k; ++dy) {
            if (!coord_offset_ok(c.y, dy)) continue;
            for (int64_t dx = -k; dx <= k; ++dx) {
                if (!coord_offset_ok(c.x, dx)) continue;
                ak_grid_cell n = {(int32_t)(c.x + dx), (int32_t)(c.y + dy), (int32_t)(c.z + dz)};
                uint32_t m = ak_grid_cell_find(grid, n);
                if (m != UINT32_MAX)
                    total = query_cell(grid, m, q.x, q.y, q.z, r2, out_indices, total);
            }
        }
    }
    return total;
}

/* ---- public: all pairs ------------------------------------------------------------------ */

typedef struct pair_task {
    const ak_grid* grid;
    float r2;
    int64_t rings;
    bool all_cells, avx512;
    uint32_t cell_begin, cell_end;
    ak_grid_pair* out;
    size_t capacity;
    size_t count;
} pair_task;

static inline void emit(pair_task* t, uint32_t a, uint32_t b) {
    if (t->count < t->capacity) {
        ak_grid_pair p = a < b ? (ak_grid_pair){a, b} : (ak_grid_pair){b, a};
        t->out[t->count] = p;
    }
    t->count++;
}

/* Pairs of sorted entries a in [a0, a1), b in [b(a), b1) where b(a) = a + 1 inside one cell
 * (same) and b0 otherwise. When the output has room for every candidate, hits are written
 * without a branch (a miss writes a slot the next hit overwrites). */
static inline void pairs_range(pair_task* t, uint32_t a0, uint32_t a1, uint32_t b0, uint32_t b1,
                               bool same) {
    const ak_grid* g = t->grid;
    const float* x = g->x;
    const float* y = g->y;
    const float* z = g->z;
    const uint32_t* order = g->order;
    const float r2 = t->r2;
    const uint64_t candidates = same ? (uint64_t)(a1 - a0) * (a1 - a0 - 1) / 2
                                     : (uint64_t)(a1 - a0) * (b1 - b0);
    if (candidates == 0) return; /* (and a counting run's output is NULL: no NULL + 0 below) */
    if (t->count + candidates <= t->capacity && t->avx512) {
        t->count += akp_grid_pairs_avx512(x, y, z, order, a0, a1, b0, b1, same, r2, t->out + t->count);
        return;
    }
    if (t->count + candidates <= t->capacity) {
        ak_grid_pair* out = t->out;
        size_t count = t->count;
        for (uint32_t a = a0; a < a1; ++a) {
            const float ax = x[a], ay = y[a], az = z[a];
            const uint32_t oa = order[a];
            for (uint32_t b = same ? a + 1 : b0; b < b1; ++b) {
                const float dx = x[b] - ax, dy = y[b] - ay, dz = z[b] - az;
                const uint32_t ob = order[b];
                out[count] = oa < ob ? (ak_grid_pair){oa, ob} : (ak_grid_pair){ob, oa};
                count += dx * dx + dy * dy + dz * dz < r2;
            }
        }
        t->count = count;
        return;
    }
    for (uint32_t a = a0; a < a1; ++a) {
        const float ax = x[a], ay = y[a], az = z[a];
        for (uint32_t b = same ? a + 1 : b0; b < b1; ++b) {
            const float dx = x[b] - ax, dy = y[b] - ay, dz = z[b] - az;
            if (dx * dx + dy * dy + dz * dz < r2) emit(t, order[a], order[b]);
        }
    }
}

/* Pairs between cell a and another cell b. */
static void pairs_between(pair_task* t, uint32_t ca, uint32_t cb) {
    const uint32_t* cs = t->grid->cell_start;
    pairs_range(t, cs[ca], cs[ca + 1], cs[cb], cs[cb + 1], false);
}

/* Pairs inside one cell. */
static void pairs_within(pair_task* t, uint32_t c) {
    const uint32_t* cs = t->grid->cell_start;
    pairs_range(t, cs[c], cs[c + 1], 0, cs[c + 1], true);
}

static void* pair_thread(void* arg) {
    /* Work on a copy: the tasks sit side by side in one array, and a count updated per pair
     * in shared cache lines would make the threads slower than one. */
    pair_task local = *(pair_task*)arg;
    pair_task* t = &local;
    const ak_grid* g = t->grid;
    const int64_t k = t->rings;
    t->count = 0;
    for (uint32_t m = t->cell_begin; m < t->cell_end; ++m) {
        pairs_within(t, m);
        const ak_grid_cell c = g->cell_coord[m];
        if (t->all_cells) {
            for (uint32_t o = m + 1; o < g->cell_count; ++o)
                if (cells_within(g->cell_coord[o], c, k)) pairs_between(t, m, o);
            continue;
        }
        /* The forward half of the stencil: offsets after (0,0,0) in (dz, dy, dx) order. */
        for (int64_t dz = 0; dz <= k; ++dz) {
            if (!coord_offset_ok(c.z, dz)) continue;
            for (int64_t dy = dz == 0 ? 0 : -k; dy <= k; ++dy) {
                if (!coord_offset_ok(c.y, dy)) continue;
                for (int64_t dx = (dz == 0 && dy == 0) ? 1 : -k; dx <= k; ++dx) {
                    if (!coord_offset_ok(c.x, dx)) continue;
                    ak_grid_cell n = {(int32_t)(c.x + dx), (int32_t)(c.y + dy),
                                      (int32_t)(c.z + dz)};
                    uint32_t o = ak_grid_cell_find(g, n);
                    if (o != UINT32_MAX) pairs_between(t, m, o);
                }
            }
        }
    }
    ((pair_task*)arg)->count = local.count;
    return NULL;
}

static void run_tasks(void* (*fn)(void*), pair_task* tasks, uint32_t count) {
    akp_run_tasks(fn, tasks, sizeof(pair_task), count);
}

ak_result ak_grid_pairs_validate(const ak_grid_pairs_job* job) {
    if (!job || !job->grid || !job->out_pair_count ||
        (!job->out_pairs.ptr && job->out_pairs.count > 0))
        return AK_ERR_NULL_ARG;
    if (!(job->radius > 0.0f) || !ak_finitef(job->radius) || job->thread_count > GRID_MAX_THREADS)
        return AK_ERR_BAD_ARG;
    return AK_OK;
}

ak_result ak_grid_pairs_run(const ak_grid_pairs_job* job) {
    ak_result r = ak_grid_pairs_validate(job);
    if (r != AK_OK) return r;
    const ak_grid* g = job->grid;
    *job->out_pair_count = 0;
    if (g->cell_count == 0) return AK_OK;
    uint32_t threads = job->thread_count ? job->thread_count : 1;
    if (threads > g->cell_count) threads = g->cell_count;
    const int64_t k = rings_for(g, job->radius);
    const bool all_cells = scan_all_cells(g, k);
    const bool avx512 = !job->scalar_only && akp_grid_have_avx512();
    pair_task tasks[GRID_MAX_THREADS];
    /* Contiguous cell ranges with about the same number of points each. */
    uint32_t m = 0;
    for (uint32_t t = 0; t < threads; ++t) {
        uint32_t begin = m;
        uint64_t target = (uint64_t)g->point_count * (t + 1) / threads;
        while (m < g->cell_count && (t + 1 == threads || g->cell_start[m] < target)) ++m;
        tasks[t] = (pair_task){g,     job->radius * job->radius, k, all_cells, avx512, begin,
                               m,     NULL,                      0, 0};
    }
    /* First try: each thread writes into its share of the output; if one overflows but the
     * total fits, a second pass writes at exact offsets. The content is the same either way. */
    const size_t cap = job->out_pairs.count;
    for (uint32_t t = 0; t < threads; ++t) {
        size_t lo = cap * t / threads, hi = cap * (t + 1) / threads;
        tasks[t].out = job->out_pairs.ptr ? job->out_pairs.ptr + lo : NULL;
        tasks[t].capacity = hi - lo;
    }
    run_tasks(pair_thread, tasks, threads);
    size_t total = 0;
    bool overflow = false;
    for (uint32_t t = 0; t < threads; ++t) {
        total += tasks[t].count;
        overflow = overflow || tasks[t].count > tasks[t].capacity;
    }
    *job->out_pair_count = total;
    if (total > cap) return AK_ERR_SPAN_SMALL;
    if (total == 0) return AK_OK;
    /* Exact offsets; threads that fit move their pairs there (leftward moves in increasing
     * order, then rightward moves in decreasing order, so no block overwrites one not yet
     * moved), and threads that overflowed their share run again into their exact place. */
    size_t offset[GRID_MAX_THREADS];
    size_t off = 0;
    for (uint32_t t = 0; t < threads; ++t) offset[t] = off, off += tasks[t].count;
    for (uint32_t t = 0; t < threads; ++t)
        if (!(tasks[t].count > tasks[t].capacity) && job->out_pairs.ptr + offset[t] <= tasks[t].out)
            memmove(job->out_pairs.ptr + offset[t], tasks[t].out,
                    tasks[t].count * sizeof(ak_grid_pair));
    for (uint32_t t = threads; t-- > 0;)
        if (!(tasks[t].count > tasks[t].capacity) && job->out_pairs.ptr + offset[t] > tasks[t].out)
            memmove(job->out_pairs.ptr + offset[t], tasks[t].out,
                    tasks[t].count * sizeof(ak_grid_pair));
    if (overflow) {
        pair_task again[GRID_MAX_THREADS];
        uint32_t rerun = 0;
        for (uint32_t t = 0; t < threads; ++t) {
            if (!(tasks[t].count > tasks[t].capacity)) continue;
            again[rerun] = tasks[t];
            again[rerun].out = job->out_pairs.ptr + offset[t];
            again[rerun].capacity = tasks[t].count;
            ++rerun;
        }
        run_tasks(pair_thread, again, rerun);
    }
    return AK_OK;
}

/* ---- public: work estimate ---------------------------------------------------------- */

uint64_t ak_grid_candidate_count(const ak_grid* grid, float radius) {
    if (!grid || grid->cell_count == 0 || !(radius > 0.0f) || !ak_finitef(radius)) return 0;
    const ak_grid* g = grid;
    const int64_t k = rings_for(g, radius);
    const bool all_cells = scan_all_cells(g, k);
    uint64_t total = 0;
    for (uint32_t m = 0; m < g->cell_count; ++m) {
        const uint64_t na = g->cell_start[m + 1] - g->cell_start[m];
        total += na * (na - 1) / 2;
        const ak_grid_cell c = g->cell_coord[m];
        if (all_cells) {
            for (uint32_t o = m + 1; o < g->cell_count; ++o)
                if (cells_within(g->cell_coord[o], c, k)) total += na * (g->cell_start[o + 1] - g->cell_start[o]);
            continue;
        }
        for (int64_t dz = 0; dz <= k; ++dz) { /* the forward half of the stencil, as pair_thread */
            if (!coord_offset_ok(c.z, dz)) continue;
            for (int64_t dy = dz == 0 ? 0 : -k; dy <= k; ++dy) {
                if (!coord_offset_ok(c.y, dy)) continue;
                for (int64_t dx = (dz == 0 && dy == 0) ? 1 : -k; dx <= k; ++dx) {
                    if (!coord_offset_ok(c.x, dx)) continue;
                    ak_grid_cell n = {(int32_t)(c.x + dx), (int32_t)(c.y + dy), (int32_t)(c.z + dz)};
                    uint32_t o = ak_grid_cell_find(g, n);
                    if (o != UINT32_MAX) total += na * (g->cell_start[o + 1] - g->cell_start[o]);
                }
            }
        }
    }
    return total;
}

/* ---- public: per-point neighbour lists (CSR) -------------------------------------------- */

size_t akp_grid_row_scalar(const float* x, const float* y, const float* z, const uint32_t* order,
                           const akp_grid_range* ranges, uint32_t range_count, uint32_t self,
                           float qx, float qy, float qz, float r2, uint32_t* out) {
    /* No branch on the hits (a quarter of the candidates, at random): counted as 0/1, and
     * written to a local block first (a miss writes a slot the next hit overwrites). */
    size_t count = 0;
    if (!out) { /* the counting pass: a plain reduction the compiler can vectorise */
        for (uint32_t r = 0; r < range_count; ++r) {
            uint32_t k = 0;
            for (uint32_t b = ranges[r].begin; b < ranges[r].end; ++b) {
                const float dx = x[b] - qx, dy = y[b] - qy, dz = z[b] - qz;
                k += (uint32_t)((dx * dx + dy * dy + dz * dz < r2) & (b != self));
            }
            count += k;
        }
        return count;
    }
    uint32_t block[32];
    for (uint32_t r = 0; r < range_count; ++r)
        for (uint32_t b0 = ranges[r].begin; b0 < ranges[r].end; b0 += 32) {
            const uint32_t b1 = ranges[r].end - b0 > 32 ? b0 + 32 : ranges[r].end;
            size_t k = 0;
            for (uint32_t b = b0; b < b1; ++b) {
                const float dx = x[b] - qx, dy = y[b] - qy, dz = z[b] - qz;
                block[k] = order[b];
                k += (size_t)((dx * dx + dy * dy + dz * dz < r2) & (b != self));
            }
            if (out) memcpy(out + count, block, k * sizeof *block);
            count += k;
        }
    return count;
}

#define GRID_ROW_RANGES 27u /* the 3 x 3 x 3 block; wider stencils go in chunks */

typedef struct row_task {
    const ak_grid* grid;
    float r2;
    int64_t rings;
    bool all_cells, avx512;
    uint32_t cell_begin, cell_end;
    uint32_t* offsets; /* [point_count + 1] */
    uint32_t* indices; /* NULL: count pass (counts into offsets[i + 1]) */
} row_task;

/* The occupied cells around cell m in ak_grid_query's order, GRID_ROW_RANGES at a time: fills
 * ranges from *cursor on and returns how many (0 when done). */
static uint32_t next_ranges(const row_task* t, uint32_t m, uint64_t* cursor, akp_grid_range* ranges) {
    const ak_grid* g = t->grid;
    const ak_grid_cell c = g->cell_coord[m];
    const int64_t k = t->rings, side = 2 * k + 1;
    uint32_t n = 0;
    if (t->all_cells) {
        for (; *cursor < g->cell_count && n < GRID_ROW_RANGES; ++*cursor) {
            const uint32_t o = (uint32_t)*cursor;
            if (cells_within(g->cell_coord[o], c, k))
                ranges[n++] = (akp_grid_range){g->cell_start[o], g->cell_start[o + 1]};
        }
        return n;
    }
    if (k == 1 && *cursor == 0) { /* the 3 x 3 x 3 block: no division per cell */
        for (int64_t dz = -1; dz <= 1; ++dz) {
            if (!coord_offset_ok(c.z, dz)) continue;
            for (int64_t dy = -1; dy <= 1; ++dy) {
                if (!coord_offset_ok(c.y, dy)) continue;
                for (int64_t dx = -1; dx <= 1; ++dx) {
                    if (!coord_offset_ok(c.x, dx)) continue;
                    const ak_grid_cell nc = {(int32_t)(c.x + dx), (int32_t)(c.y + dy), (int32_t)(c.z + dz)};
                    const uint32_t o = ak_grid_cell_find(g, nc);
                    if (o != UINT32_MAX) ranges[n++] = (akp_grid_range){g->cell_start[o], g->cell_start[o + 1]};
                }
            }
        }
        *cursor = 27;
        return n;
    }
    const uint64_t total = (uint64_t)(side * side * side);
    for (; *cursor < total && n < GRID_ROW_RANGES; ++*cursor) {
        const int64_t s = (int64_t)*cursor;
        const int64_t dz = s / (side * side) - k, dy = s / side % side - k, dx = s % side - k;
        if (!coord_offset_ok(c.x, dx) || !coord_offset_ok(c.y, dy) || !coord_offset_ok(c.z, dz))
            continue;
        const ak_grid_cell nc = {(int32_t)(c.x + dx), (int32_t)(c.y + dy), (int32_t)(c.z + dz)};
        const uint32_t o = ak_grid_cell_find(g, nc);
        if (o != UINT32_MAX) ranges[n++] = (akp_grid_range){g->cell_start[o], g->cell_start[o + 1]};
    }
    return n;
}

static void* row_thread(void* arg) {
    const row_task* t = (const row_task*)arg;
    const ak_grid* g = t->grid;
    size_t (*row)(const float*, const float*, const float*, const uint32_t*, const akp_grid_range*,
                  uint32_t, uint32_t, float, float, float, float, uint32_t*) =
        t->avx512 ? akp_grid_row_avx512 : akp_grid_row_scalar;
    akp_grid_range ranges[GRID_ROW_RANGES];
    for (uint32_t m = t->cell_begin; m < t->cell_end; ++m) {
        uint64_t cursor = 0;
        uint32_t nr = next_ranges(t, m, &cursor, ranges);
        const bool one_chunk = t->all_cells ? cursor >= g->cell_count
                                            : (uint64_t)(2 * t->rings + 1) * (uint64_t)(2 * t->rings + 1) *
                                                      (uint64_t)(2 * t->rings + 1) <= cursor;
        /* Neighbour cells next to each other in memory read as one range (same entries, same order). */
        uint32_t merged = 0;
        for (uint32_t r = 0; r < nr; ++r) {
            if (merged > 0 && ranges[merged - 1].end == ranges[r].begin) ranges[merged - 1].end = ranges[r].end;
            else ranges[merged++] = ranges[r];
        }
        nr = merged;
        for (uint32_t a = g->cell_start[m]; a < g->cell_start[m + 1]; ++a) {
            const uint32_t i = g->order[a];
            uint32_t* out = t->indices ? t->indices + t->offsets[i] : NULL;
            size_t count = row(g->x, g->y, g->z, g->order, ranges, nr, a, g->x[a], g->y[a], g->z[a],
                               t->r2, out);
            if (!one_chunk) { /* wide stencils: the further chunks, for this point */
                akp_grid_range more[GRID_ROW_RANGES];
                uint64_t c2 = cursor;
                uint32_t n2;
                while ((n2 = next_ranges(t, m, &c2, more)) > 0)
                    count += row(g->x, g->y, g->z, g->order, more, n2, a, g->x[a], g->y[a], g->z[a],
                                 t->r2, out ? out + count : NULL);
            }
            if (!t->indices) t->offsets[i + 1] = (uint32_t)(count < UINT32_MAX ? count : UINT32_MAX);
        }
    }
    return NULL;
}

ak_result ak_grid_neighbors_validate(const ak_grid_neighbors_job* job) {
    if (!job || !job->grid || !job->out_index_count || !job->out_offsets.ptr ||
        (!job->out_indices.ptr && job->out_indices.count > 0))
        return AK_ERR_NULL_ARG;
    if (!(job->radius > 0.0f) || !ak_finitef(job->radius) || job->thread_count > GRID_MAX_THREADS)
        return AK_ERR_BAD_ARG;
    if (job->out_offsets.count < (size_t)job->grid->point_count + 1) return AK_ERR_SPAN_SMALL;
    return AK_OK;
}

ak_result ak_grid_neighbors_run(const ak_grid_neighbors_job* job) {
    ak_result r = ak_grid_neighbors_validate(job);
    if (r != AK_OK) return r;
    const ak_grid* g = job->grid;
    const uint32_t n = g->point_count;
    uint32_t* offsets = job->out_offsets.ptr;
    *job->out_index_count = 0;
    offsets[0] = 0;
    if (n == 0) return AK_OK;
    uint32_t threads = job->thread_count ? job->thread_count : 1;
    if (threads > g->cell_count) threads = g->cell_count;
    const int64_t k = rings_for(g, job->radius);
    row_task tasks[GRID_MAX_THREADS];
    uint32_t m = 0;
    for (uint32_t t = 0; t < threads; ++t) { /* contiguous cells, about equal points each */
        uint32_t begin = m;
        uint64_t target = (uint64_t)n * (t + 1) / threads;
        while (m < g->cell_count && (t + 1 == threads || g->cell_start[m] < target)) ++m;
        tasks[t] = (row_task){g,        job->radius * job->radius, k, scan_all_cells(g, k),
                              !job->scalar_only && akp_grid_have_avx512(),
                              begin,    m,
                              offsets,  NULL};
    }
    akp_run_tasks(row_thread, tasks, sizeof(row_task), threads);
    uint64_t total = 0;
    bool over = false;
    for (uint32_t i = 0; i < n; ++i) {
        total += offsets[i + 1];
        over = over || offsets[i + 1] == UINT32_MAX;
        offsets[i + 1] = (uint32_t)(total < UINT32_MAX ? total : UINT32_MAX);
    }
    *job->out_index_count = (size_t)total;
    if (over || total >= UINT32_MAX) return AK_ERR_BUDGET;
    if (total > job->out_indices.count) return AK_ERR_SPAN_SMALL;
    for (uint32_t t = 0; t < threads; ++t) tasks[t].indices = job->out_indices.ptr;
    akp_run_tasks(row_thread, tasks, sizeof(row_task), threads);
    return AK_OK;
}
