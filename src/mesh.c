/* Triangle mesh container and geometric queries (bounds, normals, volume, closedness,
 * skin-weight validation and clean-up). */
#include <animkit/mesh.h>

#include <float.h>

#include "internal.h"

/* A mesh is one allocation: [header][ak_mesh][arrays...]. The header remembers the allocator
 * so ak_mesh_destroy needs no argument. */
typedef struct mesh_header {
    ak_allocator alloc;
    size_t total_size;
    size_t pad_; /* keeps sizeof a multiple of 16 on 64-bit targets */
} mesh_header;

#define MESH_HEADER_SIZE akp_align16(sizeof(mesh_header))

/* a * b with overflow detection; returns false on overflow. */
static bool mul_ok(size_t a, size_t b, size_t* out) {
    if (a != 0 && b > SIZE_MAX / a) return false;
    *out = a * b;
    return true;
}

/* Adds an aligned array of count * elem bytes to a running size; false on overflow. */
static bool add_array(size_t* total, size_t count, size_t elem) {
    size_t bytes;
    if (!mul_ok(count, elem, &bytes)) return false;
    if (bytes > SIZE_MAX - 64 || *total > SIZE_MAX - 64 - bytes) return false;
    *total = akp_align16(*total + bytes);
    return true;
}

static void* carve(unsigned char* base, size_t* offset, size_t count, size_t elem) {
    if (count == 0) return NULL;
    void* p = base + *offset;
    *offset = akp_align16(*offset + count * elem);
    return p;
}

ak_result ak_mesh_create(const ak_mesh_desc* desc, const ak_allocator* alloc, ak_mesh** out_mesh) {
    if (out_mesh) *out_mesh = NULL;
    if (!desc || !out_mesh) return AK_ERR_NULL_ARG;
    if (desc->vertex_count == 0) return AK_ERR_EMPTY;
    if (desc->influence_count > AK_MAX_INFLUENCES) return AK_ERR_BAD_ARG;
    if (alloc && (!alloc->alloc != !alloc->free)) return AK_ERR_BAD_ARG;

    const size_t v = desc->vertex_count, t = desc->triangle_count, m = desc->morph_target_count;
    size_t idx_count, infl_count, morph_count;
    if (!mul_ok(t, 3, &idx_count) || !mul_ok(v, desc->influence_count, &infl_count) ||
        !mul_ok(v, m, &morph_count))
        return AK_ERR_BAD_ARG;
    if (idx_count > 0 && v > (size_t)UINT32_MAX + 1u) return AK_ERR_BAD_ARG; /* indices are u32 */

    size_t total = MESH_HEADER_SIZE + akp_align16(sizeof(ak_mesh));
    bool ok = add_array(&total, v, sizeof(ak_vec3)) &&
              add_array(&total, desc->has_normals ? v : 0, sizeof(ak_vec3)) &&
              add_array(&total, desc->has_uvs ? v : 0, sizeof(ak_vec2)) &&
              add_array(&total, desc->has_colors ? v : 0, sizeof(ak_vec4)) &&
              add_array(&total, idx_count, sizeof(uint32_t)) &&
              add_array(&total, infl_count, sizeof(uint16_t)) &&
              add_array(&total, infl_count, sizeof(float)) &&
              add_array(&total, morph_count, sizeof(ak_vec3)) &&
              add_array(&total, desc->has_morph_normals ? morph_count : 0, sizeof(ak_vec3)) &&
              add_array(&total, m, sizeof(float)) && add_array(&total, m, AK_NAME_SIZE) &&
              add_array(&total, desc->has_tangents ? v : 0, sizeof(ak_vec4)) &&
              add_array(&total, desc->has_morph_tangents ? morph_count : 0, sizeof(ak_vec3));
    if (!ok) return AK_ERR_BAD_ARG;

    unsigned char* base = (unsigned char*)akp_calloc(alloc, total);
    if (!base) return AK_ERR_NO_MEMORY;
    mesh_header* h = (mesh_header*)base;
    if (alloc) h->alloc = *alloc;
    h->total_size = total;
    ak_mesh* mesh = (ak_mesh*)(base + MESH_HEADER_SIZE);
    size_t off = MESH_HEADER_SIZE + akp_align16(sizeof(ak_mesh));
    mesh->vertex_count = v;
    mesh->triangle_count = t;
    mesh->influence_count = desc->influence_count;
    mesh->morph_target_count = m;
    if (desc->name) snprintf(mesh->name, sizeof(mesh->name), "%s", desc->name);
    mesh->positions = (ak_vec3*)carve(base, &off, v, sizeof(ak_vec3));
    mesh->normals = (ak_vec3*)carve(base, &off, desc->has_normals ? v : 0, sizeof(ak_vec3));
    mesh->uvs = (ak_vec2*)carve(base, &off, desc->has_uvs ? v : 0, sizeof(ak_vec2));
    mesh->colors = (ak_vec4*)carve(base, &off, desc->has_colors ? v : 0, sizeof(ak_vec4));
    mesh->indices = (uint32_t*)carve(base, &off, idx_count, sizeof(uint32_t));
    mesh->joints = (uint16_t*)carve(base, &off, infl_count, sizeof(uint16_t));
    mesh->weights = (float*)carve(base, &off, infl_count, sizeof(float));
    mesh->morph_positions = (ak_vec3*)carve(base, &off, morph_count, sizeof(ak_vec3));
    mesh->morph_normals =
        (ak_vec3*)carve(base, &off, desc->has_morph_normals ? morph_count : 0, sizeof(ak_vec3));
    mesh->morph_weights = (float*)carve(base, &off, m, sizeof(float));
    mesh->morph_names = (char(*)[AK_NAME_SIZE])carve(base, &off, m, AK_NAME_SIZE);
    mesh->tangents = (ak_vec4*)carve(base, &off, desc->has_tangents ? v : 0, sizeof(ak_vec4));
    mesh->morph_tangents =
        (ak_vec3*)carve(base, &off, desc->has_morph_tangents ? morph_count : 0, sizeof(ak_vec3));
    AK_ASSERT(off <= total);
    *out_mesh = mesh;
    return AK_OK;
}

void ak_mesh_destroy(ak_mesh* mesh) {
    if (!mesh) return;
    unsigned char* base = (unsigned char*)mesh - MESH_HEADER_SIZE;
    ak_allocator a = ((mesh_header*)base)->alloc;
    akp_free(&a, base);
}

ak_result ak_mesh_clone(const ak_mesh* mesh, const ak_allocator* alloc, ak_mesh** out_mesh) {
    if (out_mesh) *out_mesh = NULL;
    if (!mesh || !out_mesh) return AK_ERR_NULL_ARG;
    ak_mesh_desc d = {
        .vertex_count = mesh->vertex_count,
        .triangle_count = mesh->triangle_count,
        .influence_count = mesh->influence_count,
        .morph_target_count = mesh->morph_target_count,
        .has_normals = mesh->normals != NULL,
        .has_uvs = mesh->uvs != NULL,
        .has_colors = mesh->colors != NULL,
        .has_morph_normals = mesh->morph_normals != NULL,
        .name = mesh->name,
        .has_tangents = mesh->tangents != NULL,
        .has_morph_tangents = mesh->morph_tangents != NULL,
    };
    ak_mesh* c = NULL;
    ak_result r = ak_mesh_create(&d, alloc, &c);
    if (r != AK_OK) return r;
    const size_t v = mesh->vertex_count, infl = v * mesh->influence_count,
                 morph = v * mesh->morph_target_count;
    if (mesh->positions) memcpy(c->positions, mesh->positions, v * sizeof(ak_vec3));
    if (mesh->normals) memcpy(c->normals, mesh->normals, v * sizeof(ak_vec3));
    if (mesh->uvs) memcpy(c->uvs, mesh->uvs, v * sizeof(ak_vec2));
    if (mesh->colors) memcpy(c->colors, mesh->colors, v * sizeof(ak_vec4));
    if (mesh->indices && mesh->triangle_count)
        memcpy(c->indices, mesh->indices, 3 * mesh->triangle_count * sizeof(uint32_t));
    if (infl && mesh->joints) memcpy(c->joints, mesh->joints, infl * sizeof(uint16_t));
    if (infl && mesh->weights) memcpy(c->weights, mesh->weights, infl * sizeof(float));
    if (morph && mesh->morph_positions)
        memcpy(c->morph_positions, mesh->morph_positions, morph * sizeof(ak_vec3));
    if (morph && mesh->morph_normals)
        memcpy(c->morph_normals, mesh->morph_normals, morph * sizeof(ak_vec3));
    if (mesh->morph_target_count && mesh->morph_weights)
        memcpy(c->morph_weights, mesh->morph_weights, mesh->morph_target_count * sizeof(float));
    if (mesh->morph_target_count && mesh->morph_names)
        memcpy(c->morph_names, mesh->morph_names, mesh->morph_target_count * AK_NAME_SIZE);
    if (mesh->tangents) memcpy(c->tangents, mesh->tangents, v * sizeof(ak_vec4));
    if (morph && mesh->morph_tangents)
        memcpy(c->morph_tangents, mesh->morph_tangents, morph * sizeof(ak_vec3));
    *out_mesh = c;
    return AK_OK;
}

ak_result ak_mesh_validate(const ak_mesh* mesh, ak_diag* diag) {
    if (!mesh) return AK_ERR_NULL_ARG;
    if (mesh->vertex_count && !mesh->positions) return AK_ERR_NULL_ARG;
    if (mesh->triangle_count && !mesh->indices) return AK_ERR_NULL_ARG;
    for (size_t t = 0; t < mesh->triangle_count; ++t)
        for (int k = 0; k < 3; ++k)
            if (mesh->indices[3 * t + (size_t)k] >= mesh->vertex_count) {
                akp_diag_set(diag, NULL,
                             "mesh '%s': triangle %zu uses vertex %u, but there are %zu vertices",
                             mesh->name, t, (unsigned)mesh->indices[3 * t + (size_t)k],
                             mesh->vertex_count);
                return AK_ERR_BAD_INDEX;
            }
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        if (!ak_vec3_is_finite(mesh->positions[v])) {
            akp_diag_set(diag, NULL, "mesh '%s': vertex %zu has a non-finite position", mesh->name,
                         v);
            return AK_ERR_BAD_DATA;
        }
        if (mesh->normals && !ak_vec3_is_finite(mesh->normals[v])) {
            akp_diag_set(diag, NULL, "mesh '%s': vertex %zu has a non-finite normal", mesh->name,
                         v);
            return AK_ERR_BAD_DATA;
        }
    }
    return AK_OK;
}

void ak_points_bounds(ak_vec3_cspan points, ak_vec3* out_min, ak_vec3* out_max) {
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    bool any = false;
    for (size_t i = 0; points.ptr && i < points.count; ++i) {
        if (!ak_vec3_is_finite(points.ptr[i])) continue;
        lo = ak_vec3_min(lo, points.ptr[i]);
        hi = ak_vec3_max(hi, points.ptr[i]);
        any = true;
    }
    if (!any) lo = hi = ak_vec3_zero();
    if (out_min) *out_min = lo;
    if (out_max) *out_max = hi;
}

void ak_mesh_bounds(const ak_mesh* mesh, ak_vec3* out_min, ak_vec3* out_max) {
    ak_vec3_cspan p = {mesh ? mesh->positions : NULL, mesh ? mesh->vertex_count : 0};
    ak_points_bounds(p, out_min, out_max);
}

ak_result ak_normals_compute(ak_vec3_cspan positions, ak_u32_cspan indices,
                             ak_vec3_span out_normals) {
    if (!out_normals.ptr || (positions.count && !positions.ptr) || (indices.count && !indices.ptr))
        return AK_ERR_NULL_ARG;
    if (out_normals.count < positions.count) return AK_ERR_SPAN_SMALL;
    const size_t tri = indices.count / 3;
    for (size_t i = 0; i < 3 * tri; ++i)
        if (indices.ptr[i] >= positions.count) return AK_ERR_BAD_INDEX;
    for (size_t v = 0; v < positions.count; ++v) out_normals.ptr[v] = ak_vec3_zero();
    for (size_t t = 0; t < tri; ++t) {
        uint32_t a = indices.ptr[3 * t], b = indices.ptr[3 * t + 1], c = indices.ptr[3 * t + 2];
        /* The unnormalised cross product is twice the area times the unit normal. */
        ak_vec3 n = ak_vec3_cross(ak_vec3_sub(positions.ptr[b], positions.ptr[a]),
                                  ak_vec3_sub(positions.ptr[c], positions.ptr[a]));
        if (!ak_vec3_is_finite(n)) continue;
        out_normals.ptr[a] = ak_vec3_add(out_normals.ptr[a], n);
        out_normals.ptr[b] = ak_vec3_add(out_normals.ptr[b], n);
        out_normals.ptr[c] = ak_vec3_add(out_normals.ptr[c], n);
    }
    for (size_t v = 0; v < positions.count; ++v) {
        ak_vec3 n = out_normals.ptr[v];
        float len = ak_vec3_length(n);
        out_normals.ptr[v] = (len > 1e-30f && ak_finitef(len)) ? ak_vec3_scale(n, 1.0f / len)
                                                               : ak_vec3_make(0.0f, 1.0f, 0.0f);
    }
    return AK_OK;
}

/* Hash-table size for welding n vertices: a power of two >= 2n (>= 16), 0 on overflow. */
static size_t weld_table_size(size_t n) {
    size_t t = 16;
    while (t < 2 * n) {
        if (t > SIZE_MAX / 4) return 0;
        t *= 2;
    }
    return t;
}

size_t ak_normals_welded_scratch_count(size_t vertex_count) {
    if (vertex_count > SIZE_MAX / 8 || vertex_count >= UINT32_MAX) return SIZE_MAX;
    size_t t = weld_table_size(vertex_count);
    return t ? vertex_count + t : SIZE_MAX;
}

/* Coordinate bits with -0 folded onto +0, so both weld. */
static uint32_t coord_bits(float f) {
    uint32_t u;
    if (f == 0.0f) f = 0.0f;
    memcpy(&u, &f, sizeof u);
    return u;
}

static bool same_position(ak_vec3 a, ak_vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* rep[v]: the first vertex at v's position (open addressing, linear probing in table, whose
 * size T is a power of two >= 2n); non-finite positions stand for themselves. */
static void weld_reps(const ak_vec3* positions, size_t n, uint32_t* rep, uint32_t* table, size_t T) {
    const size_t mask = T - 1;
    for (size_t k = 0; k < T; ++k) table[k] = UINT32_MAX;
    for (size_t v = 0; v < n; ++v) {
        ak_vec3 p = positions[v];
        rep[v] = (uint32_t)v;
        if (!ak_vec3_is_finite(p)) continue;
        uint32_t h = coord_bits(p.x) * 0x9E3779B1u;
        h = (h ^ (h >> 15) ^ coord_bits(p.y)) * 0x85EBCA77u;
        h = (h ^ (h >> 13) ^ coord_bits(p.z)) * 0xC2B2AE3Du;
        h ^= h >> 16;
        for (size_t k = h & mask;; k = (k + 1) & mask) {
            if (table[k] == UINT32_MAX) {
                table[k] = (uint32_t)v;
                break;
            }
            if (same_position(positions[table[k]], p)) {
                rep[v] = table[k];
                break;
            }
        }
    }
}

ak_result ak_normals_compute_welded(ak_vec3_cspan positions, ak_u32_cspan indices,
                                    ak_u32_span scratch, ak_vec3_span out_normals) {
    if (!out_normals.ptr || !scratch.ptr || (positions.count && !positions.ptr) ||
        (indices.count && !indices.ptr))
        return AK_ERR_NULL_ARG;
    const size_t n = positions.count;
    if (out_normals.count < n) return AK_ERR_SPAN_SMALL;
    size_t need = ak_normals_welded_scratch_count(n);
    if (need == SIZE_MAX || scratch.count < need) return AK_ERR_SPAN_SMALL;
    const size_t tri = indices.count / 3;
    for (size_t i = 0; i < 3 * tri; ++i)
        if (indices.ptr[i] >= n) return AK_ERR_BAD_INDEX;
    /* rep[v]: the first vertex at v's position */
    uint32_t* rep = scratch.ptr;
    weld_reps(positions.ptr, n, rep, scratch.ptr + n, need - n);
    for (size_t v = 0; v < n; ++v) out_normals.ptr[v] = ak_vec3_zero();
    for (size_t t = 0; t < tri; ++t) {
        uint32_t a = indices.ptr[3 * t], b = indices.ptr[3 * t + 1], c = indices.ptr[3 * t + 2];
        ak_vec3 fn = ak_vec3_cross(ak_vec3_sub(positions.ptr[b], positions.ptr[a]),
                                   ak_vec3_sub(positions.ptr[c], positions.ptr[a]));
        if (!ak_vec3_is_finite(fn)) continue;
        out_normals.ptr[rep[a]] = ak_vec3_add(out_normals.ptr[rep[a]], fn);
        out_normals.ptr[rep[b]] = ak_vec3_add(out_normals.ptr[rep[b]], fn);
        out_normals.ptr[rep[c]] = ak_vec3_add(out_normals.ptr[rep[c]], fn);
    }
    /* a representative comes before the vertices it stands for: one pass in order */
    for (size_t v = 0; v < n; ++v) {
        if (rep[v] != v) {
            out_normals.ptr[v] = out_normals.ptr[rep[v]];
            continue;
        }
        ak_vec3 nv = out_normals.ptr[v];
        float len = ak_vec3_length(nv);
        out_normals.ptr[v] = (len > 1e-30f && ak_finitef(len)) ? ak_vec3_scale(nv, 1.0f / len)
                                                               : ak_vec3_make(0.0f, 1.0f, 0.0f);
    }
    return AK_OK;
}

ak_result ak_mesh_compute_normals(ak_mesh* mesh) {
    if (!mesh) return AK_ERR_NULL_ARG;
    if (!mesh->normals) return AK_OK;
    ak_vec3_cspan p = {mesh->positions, mesh->vertex_count};
    ak_u32_cspan idx = {mesh->indices, mesh->indices ? 3 * mesh->triangle_count : 0};
    ak_vec3_span out = {mesh->normals, mesh->vertex_count};
    return ak_normals_compute(p, idx, out);
}

double ak_volume_compute(ak_vec3_cspan positions, ak_u32_cspan indices) {
    if (!positions.ptr || !indices.ptr) return 0.0;
    double vol = 0.0;
    const size_t tri = indices.count / 3;
    for (size_t t = 0; t < tri; ++t) {
        uint32_t i0 = indices.ptr[3 * t], i1 = indices.ptr[3 * t + 1], i2 = indices.ptr[3 * t + 2];
        if (i0 >= positions.count || i1 >= positions.count || i2 >= positions.count) continue;
        ak_vec3 a = positions.ptr[i0], b = positions.ptr[i1], c = positions.ptr[i2];
        /* Signed volume of the tetrahedron (origin, a, b, c): a . (b x c) / 6. */
        double cx = (double)b.y * c.z - (double)b.z * c.y;
        double cy = (double)b.z * c.x - (double)b.x * c.z;
        double cz = (double)b.x * c.y - (double)b.y * c.x;
        double v = (double)a.x * cx + (double)a.y * cy + (double)a.z * cz;
        if (v - v == 0.0) vol += v;
    }
    return vol / 6.0;
}

static int cmp_u64(const void* a, const void* b) {
    uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
    return (x > y) - (x < y);
}

bool ak_mesh_is_closed_oriented(const ak_mesh* mesh) {
    if (!mesh || mesh->triangle_count == 0 || !mesh->indices) return false;
    const size_t e = 3 * mesh->triangle_count;
    /* Temporary heap memory for the sorted directed-edge list (a query, not an object). */
    uint64_t* edges = (uint64_t*)malloc(e * sizeof(uint64_t));
    if (!edges) return false;
    bool ok = true;
    for (size_t t = 0; t < mesh->triangle_count && ok; ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = mesh->indices[3 * t + (size_t)k],
                     b = mesh->indices[3 * t + (size_t)((k + 1) % 3)];
            if (a == b || a >= mesh->vertex_count || b >= mesh->vertex_count) ok = false;
            edges[3 * t + (size_t)k] = ((uint64_t)a << 32) | b;
        }
    if (ok) {
        qsort(edges, e, sizeof(uint64_t), cmp_u64);
        /* Each directed edge exactly once, and its reverse present: then every undirected edge
         * has exactly two triangles traversing it in opposite directions. */
        for (size_t i = 0; i < e && ok; ++i) {
            if (i + 1 < e && edges[i] == edges[i + 1]) ok = false;
            uint64_t rev = (edges[i] << 32) | (edges[i] >> 32);
            if (ok && !bsearch(&rev, edges, e, sizeof(uint64_t), cmp_u64)) ok = false;
        }
    }
    free(edges);
    return ok;
}

ak_result ak_mesh_validate_weights(const ak_mesh* mesh, size_t joint_count, float tolerance,
                                   ak_diag* diag) {
    if (!mesh) return AK_ERR_NULL_ARG;
    const uint32_t k = mesh->influence_count;
    if (k == 0) return AK_OK;
    if (!mesh->joints || !mesh->weights) return AK_ERR_NULL_ARG;
    const double tol = (tolerance > 0.0f && ak_finitef(tolerance)) ? (double)tolerance : 1e-3;
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        double sum = 0.0;
        for (uint32_t i = 0; i < k; ++i) {
            float w = mesh->weights[v * k + i];
            uint16_t j = mesh->joints[v * k + i];
            if (!ak_finitef(w) || w < 0.0f) {
                akp_diag_set(diag, NULL, "mesh '%s': vertex %zu influence %u has weight %g",
                             mesh->name, v, (unsigned)i, (double)w);
                return AK_ERR_BAD_WEIGHTS;
            }
            if (j >= joint_count) {
                akp_diag_set(diag, NULL,
                             "mesh '%s': vertex %zu influence %u refers to joint %u of %zu",
                             mesh->name, v, (unsigned)i, (unsigned)j, joint_count);
                return AK_ERR_BAD_INDEX;
            }
            sum += w;
        }
        if (fabs(sum - 1.0) > tol) {
            akp_diag_set(diag, NULL, "mesh '%s': vertex %zu weights sum to %.6g, not 1", mesh->name,
                         v, sum);
            return AK_ERR_BAD_WEIGHTS;
        }
    }
    return AK_OK;
}

/* Most slots per vertex that ak_weights_normalize reads (an importer may gather several
 * glTF JOINTS_n/WEIGHTS_n sets into one wide stride before limiting). */
#define WEIGHTS_READ_MAX 64

void ak_weights_normalize(uint16_t* joints, float* weights, size_t vertex_count,
                          uint32_t influence_count, uint32_t max_influences, float min_weight) {
    if (!joints || !weights || influence_count == 0) return;
    uint32_t keep_max = max_influences ? max_influences : 4u;
    if (keep_max > influence_count) keep_max = influence_count;
    if (!(min_weight >= 0.0f)) min_weight = 0.0f;
    for (size_t v = 0; v < vertex_count; ++v) {
        uint16_t* jv = joints + v * influence_count;
        float* wv = weights + v * influence_count;
        const uint16_t first_joint = jv[0];
        uint16_t j[WEIGHTS_READ_MAX];
        float w[WEIGHTS_READ_MAX];
        uint32_t n = 0;
        const uint32_t read =
            influence_count < WEIGHTS_READ_MAX ? influence_count : WEIGHTS_READ_MAX;
        for (uint32_t i = 0; i < read; ++i) {
            float wi = wv[i];
            if (!(wi > 0.0f) || !ak_finitef(wi)) continue;
            uint32_t m = 0;
            while (m < n && j[m] != jv[i]) ++m;
            if (m < n) {
                w[m] += wi;
            } else {
                j[n] = jv[i];
                w[n] = wi;
                ++n;
            }
        }
        /* Insertion sort: decreasing weight, then increasing joint index for determinism. */
        for (uint32_t a = 1; a < n; ++a) {
            uint16_t jj = j[a];
            float ww = w[a];
            uint32_t b = a;
            while (b > 0 && (w[b - 1] < ww || (w[b - 1] == ww && j[b - 1] > jj))) {
                w[b] = w[b - 1];
                j[b] = j[b - 1];
                --b;
            }
            w[b] = ww;
            j[b] = jj;
        }
        if (n > keep_max) n = keep_max;
        while (n > 1 && w[n - 1] < min_weight) --n; /* the largest always stays */
        double sum = 0.0;
        for (uint32_t i = 0; i < n; ++i) sum += w[i];
        if (n == 0 || !(sum > 0.0) || sum - sum != 0.0) {
            j[0] = first_joint;
            w[0] = 1.0f;
            n = 1;
        } else {
            float partial = 0.0f;
            for (uint32_t i = 0; i + 1 < n; ++i) {
                w[i] = (float)(w[i] / sum);
                partial += w[i];
            }
            /* The smallest weight absorbs the rounding so the float sum is 1 to ~1 ulp. */
            w[n - 1] = n == 1 ? 1.0f : ak_maxf(1.0f - partial, 0.0f);
        }
        for (uint32_t i = 0; i < influence_count; ++i) {
            jv[i] = i < n ? j[i] : 0;
            wv[i] = i < n ? w[i] : 0.0f;
        }
    }
}

/* ---- self-intersections ------------------------------------------------------------------ */

/* Orientation predicates in double precision on float input. The sign is that of the 3x3
 * determinant; exactly zero means coplanar (or collinear in 2D). */
typedef struct dvec3 {
    double x, y, z;
} dvec3;

static dvec3 to_d(ak_vec3 v) { return (dvec3){v.x, v.y, v.z}; }

/* Sign of det[b-a, c-a, d-a]: > 0 when d is on the side of plane (a, b, c) its normal
 * (b-a) x (c-a) points to. */
static int orient3(dvec3 a, dvec3 b, dvec3 c, dvec3 d) {
    double bx = b.x - a.x, by = b.y - a.y, bz = b.z - a.z;
    double cx = c.x - a.x, cy = c.y - a.y, cz = c.z - a.z;
    double dx = d.x - a.x, dy = d.y - a.y, dz = d.z - a.z;
    double det = bx * (cy * dz - cz * dy) - by * (cx * dz - cz * dx) + bz * (cx * dy - cy * dx);
    return (det > 0.0) - (det < 0.0);
}

typedef struct dvec2 {
    double u, v;
} dvec2;

static int orient2(dvec2 a, dvec2 b, dvec2 c) {
    double det = (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
    return (det > 0.0) - (det < 0.0);
}

/* Drops coordinate axis (0 x, 1 y, 2 z). */
static dvec2 project2(dvec3 p, int axis) {
    return axis == 0 ? (dvec2){p.y, p.z} : axis == 1 ? (dvec2){p.z, p.x} : (dvec2){p.x, p.y};
}

/* Axis of the largest normal component of triangle (a, b, c); -1 when degenerate. */
static int dominant_axis(dvec3 a, dvec3 b, dvec3 c) {
    double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
    double vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
    double nx = fabs(uy * vz - uz * vy), ny = fabs(uz * vx - ux * vz), nz = fabs(ux * vy - uy * vx);
    if (nx == 0.0 && ny == 0.0 && nz == 0.0) return -1;
    return nx >= ny && nx >= nz ? 0 : ny >= nz ? 1 : 2;
}

/* Closed point-in-triangle in 2D (triangle non-degenerate). */
static bool point_in_tri2(dvec2 x, dvec2 p, dvec2 q, dvec2 r) {
    int o1 = orient2(p, q, x), o2 = orient2(q, r, x), o3 = orient2(r, p, x);
    bool pos = o1 > 0 || o2 > 0 || o3 > 0, neg = o1 < 0 || o2 < 0 || o3 < 0;
    return !(pos && neg);
}

static bool interval_overlap(double a0, double a1, double b0, double b1) {
    double alo = a0 < a1 ? a0 : a1, ahi = a0 < a1 ? a1 : a0;
    double blo = b0 < b1 ? b0 : b1, bhi = b0 < b1 ? b1 : b0;
    return alo <= bhi && blo <= ahi;
}

/* Closed segment-segment intersection in 2D. */
static bool seg_seg2(dvec2 a, dvec2 b, dvec2 c, dvec2 d) {
    int o1 = orient2(a, b, c), o2 = orient2(a, b, d);
    int o3 = orient2(c, d, a), o4 = orient2(c, d, b);
    if ((o1 == 0 && o2 == 0) || (o3 == 0 && o4 == 0)) /* collinear: overlapping extents */
        return interval_overlap(a.u, b.u, c.u, d.u) && interval_overlap(a.v, b.v, c.v, d.v);
    if (o1 * o2 > 0 || o3 * o4 > 0) return false;
    return true;
}

/* Closed segment (a, b) against the closed triangle (p, q, r), all in one plane whose
 * dominant normal axis is axis. */
static bool seg_tri_coplanar(dvec3 a, dvec3 b, dvec3 p, dvec3 q, dvec3 r, int axis) {
    dvec2 a2 = project2(a, axis), b2 = project2(b, axis);
    dvec2 p2 = project2(p, axis), q2 = project2(q, axis), r2 = project2(r, axis);
    if (point_in_tri2(a2, p2, q2, r2) || point_in_tri2(b2, p2, q2, r2)) return true;
    return seg_seg2(a2, b2, p2, q2) || seg_seg2(a2, b2, q2, r2) || seg_seg2(a2, b2, r2, p2);
}

/* Closed segment (a, b) against the closed, non-degenerate triangle t[0..2]. */
static bool seg_tri(dvec3 a, dvec3 b, const dvec3 t[3], int axis) {
    int sa = orient3(t[0], t[1], t[2], a), sb = orient3(t[0], t[1], t[2], b);
    if (sa * sb > 0) return false;
    if (sa == 0 && sb == 0) return seg_tri_coplanar(a, b, t[0], t[1], t[2], axis);
    /* The segment meets the plane; its line pierces the closed triangle iff the three signed
     * volumes against the triangle's edges do not disagree. */
    int o1 = orient3(a, b, t[0], t[1]), o2 = orient3(a, b, t[1], t[2]), o3 = orient3(a, b, t[2], t[0]);
    bool pos = o1 > 0 || o2 > 0 || o3 > 0, neg = o1 < 0 || o2 < 0 || o3 < 0;
    return !(pos && neg);
}

/* Exact-sign test of two closed, non-degenerate triangles (ax: their dominant axes). Two
 * triangles in different planes meet iff an edge of one meets the other (the ends of the
 * common segment on the planes' line lie on edges); coplanar ones meet iff edges cross or a
 * vertex of one lies in the other. */
static bool tri_tri(const dvec3 A[3], int axA, const dvec3 B[3], int axB) {
    int dB[3], dA[3];
    for (int k = 0; k < 3; ++k) dB[k] = orient3(A[0], A[1], A[2], B[k]);
    if ((dB[0] > 0 && dB[1] > 0 && dB[2] > 0) || (dB[0] < 0 && dB[1] < 0 && dB[2] < 0)) return false;
    for (int k = 0; k < 3; ++k) dA[k] = orient3(B[0], B[1], B[2], A[k]);
    if ((dA[0] > 0 && dA[1] > 0 && dA[2] > 0) || (dA[0] < 0 && dA[1] < 0 && dA[2] < 0)) return false;
    if ((dB[0] == 0 && dB[1] == 0 && dB[2] == 0) || (dA[0] == 0 && dA[1] == 0 && dA[2] == 0)) {
        dvec2 a[3], b[3];
        for (int k = 0; k < 3; ++k) a[k] = project2(A[k], axA), b[k] = project2(B[k], axA);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                if (seg_seg2(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])) return true;
        return point_in_tri2(a[0], b[0], b[1], b[2]) || point_in_tri2(b[0], a[0], a[1], a[2]);
    }
    for (int i = 0; i < 3; ++i)
        if (seg_tri(A[i], A[(i + 1) % 3], B, axB) || seg_tri(B[i], B[(i + 1) % 3], A, axA)) return true;
    return false;
}

bool ak_triangles_intersect(const ak_vec3 a[3], const ak_vec3 b[3]) {
    if (!a || !b) return false;
    dvec3 A[3], B[3];
    for (int k = 0; k < 3; ++k) {
        if (!ak_vec3_is_finite(a[k]) || !ak_vec3_is_finite(b[k])) return false;
        A[k] = to_d(a[k]), B[k] = to_d(b[k]);
    }
    int axA = dominant_axis(A[0], A[1], A[2]), axB = dominant_axis(B[0], B[1], B[2]);
    if (axA < 0 || axB < 0) return false;
    return tri_tri(A, axA, B, axB);
}

ak_result ak_mesh_self_intersections(ak_vec3_cspan positions, ak_u32_cspan indices, ak_u32_span out_pairs,
                                     size_t* out_count) {
    if (out_count) *out_count = 0;
    if (!out_count || !positions.ptr || (!indices.ptr && indices.count)) return AK_ERR_NULL_ARG;
    if (out_pairs.count && !out_pairs.ptr) return AK_ERR_NULL_ARG;
    const size_t nv = positions.count, nt = indices.count / 3;
    if (nv > UINT32_MAX || nt > UINT32_MAX / 8) return AK_ERR_BAD_ARG;
    for (size_t i = 0; i < 3 * nt; ++i)
        if (indices.ptr[i] >= nv) return AK_ERR_BAD_INDEX;
    for (size_t i = 0; i < nv; ++i)
        if (!ak_vec3_is_finite(positions.ptr[i])) return AK_ERR_BAD_DATA;
    if (nt < 2) return AK_OK;

    /* Weld: canonical id per vertex, shared by vertices at the same position, so triangles
     * across a UV seam (split vertices) count as adjacent. */
    const size_t wcount = ak_normals_welded_scratch_count(nv);
    uint32_t* weld = wcount != SIZE_MAX ? (uint32_t*)malloc(wcount * sizeof(uint32_t)) : NULL;
    float* box = (float*)malloc(6 * nt * sizeof(float));
    uint32_t* tri_cell = (uint32_t*)malloc(6 * nt * sizeof(uint32_t)); /* cell range lo/hi */
    if (!weld || !box || !tri_cell) {
        free(weld), free(box), free(tri_cell);
        return AK_ERR_NO_MEMORY;
    }
    weld_reps(positions.ptr, nv, weld, weld + nv, wcount - nv);

    /* Triangle bounds; degenerate triangles (zero area) get an empty box and never count. */
    double mean_ext = 0.0;
    ak_vec3 lo_all = {FLT_MAX, FLT_MAX, FLT_MAX}, hi_all = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (size_t t = 0; t < nt; ++t) {
        const uint32_t* ix = indices.ptr + 3 * t;
        ak_vec3 a = positions.ptr[ix[0]], b = positions.ptr[ix[1]], c = positions.ptr[ix[2]];
        float* bx = box + 6 * t;
        bx[0] = fminf(a.x, fminf(b.x, c.x)), bx[1] = fminf(a.y, fminf(b.y, c.y));
        bx[2] = fminf(a.z, fminf(b.z, c.z)), bx[3] = fmaxf(a.x, fmaxf(b.x, c.x));
        bx[4] = fmaxf(a.y, fmaxf(b.y, c.y)), bx[5] = fmaxf(a.z, fmaxf(b.z, c.z));
        if (dominant_axis(to_d(a), to_d(b), to_d(c)) < 0) {
            bx[0] = 1.0f, bx[3] = -1.0f; /* empty */
            continue;
        }
        lo_all = ak_vec3_make(fminf(lo_all.x, bx[0]), fminf(lo_all.y, bx[1]), fminf(lo_all.z, bx[2]));
        hi_all = ak_vec3_make(fmaxf(hi_all.x, bx[3]), fmaxf(hi_all.y, bx[4]), fmaxf(hi_all.z, bx[5]));
        double e = fmax((double)bx[3] - bx[0], fmax((double)bx[4] - bx[1], (double)bx[5] - bx[2]));
        mean_ext += e;
    }
    mean_ext /= (double)nt;
    size_t count = 0, written = 0;
    ak_result res = AK_OK;
    if (lo_all.x > hi_all.x) goto done; /* every triangle degenerate */

    /* Uniform grid over the bounds, cells about one mean triangle extent wide, at most about
     * 2 * nt cells; grown while the triangle-cell entries exceed 16 per triangle. */
    double ext[3] = {(double)hi_all.x - lo_all.x, (double)hi_all.y - lo_all.y, (double)hi_all.z - lo_all.z};
    double org[3] = {lo_all.x, lo_all.y, lo_all.z};
    double h = mean_ext > 0.0 ? mean_ext : 1.0;
    double hmin = fmax(ext[0], fmax(ext[1], ext[2])) * 1e-6;
    if (h < hmin || h == 0.0) h = hmin > 0.0 ? hmin : 1.0;
    size_t dim[3], cells = 0, entries = 0;
    for (int attempt = 0;; ++attempt, h *= 2.0) {
        for (int k = 0; k < 3; ++k) dim[k] = (size_t)fmin(ext[k] / h + 1.0, 1e6);
        cells = dim[0] * dim[1] * dim[2];
        if (cells > 2 * nt + 64 && attempt < 64) continue;
        entries = 0;
        for (size_t t = 0; t < nt; ++t) {
            const float* bx = box + 6 * t;
            if (bx[0] > bx[3]) continue;
            size_t n = 1;
            for (int k = 0; k < 3; ++k) {
                size_t a = (size_t)fmin(((double)bx[k] - org[k]) / h, (double)(dim[k] - 1));
                size_t b = (size_t)fmin(((double)bx[k + 3] - org[k]) / h, (double)(dim[k] - 1));
                tri_cell[6 * t + (size_t)k] = (uint32_t)a, tri_cell[6 * t + 3 + (size_t)k] = (uint32_t)b;
                n *= b - a + 1;
            }
            entries += n;
        }
        if (entries <= 16 * nt + 1024 || attempt >= 64) break;
    }
    uint32_t* cell_start = (uint32_t*)calloc(cells + 1, sizeof(uint32_t));
    uint32_t* cell_tri = entries <= UINT32_MAX ? (uint32_t*)malloc((entries ? entries : 1) * sizeof(uint32_t)) : NULL;
    if (!cell_start || !cell_tri) {
        free(cell_start), free(cell_tri);
        res = AK_ERR_NO_MEMORY;
        goto done;
    }
#define AKP_CELL_ID(x, y, z) (((size_t)(z) * dim[1] + (size_t)(y)) * dim[0] + (size_t)(x))
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t t = 0; t < nt; ++t) {
            const uint32_t* c = tri_cell + 6 * t;
            if (box[6 * t] > box[6 * t + 3]) continue;
            for (uint32_t z = c[2]; z <= c[5]; ++z)
                for (uint32_t y = c[1]; y <= c[4]; ++y)
                    for (uint32_t x = c[0]; x <= c[3]; ++x) {
                        size_t id = AKP_CELL_ID(x, y, z);
                        if (pass == 0)
                            ++cell_start[id + 1];
                        else
                            cell_tri[cell_start[id]++] = (uint32_t)t;
                    }
        }
        if (pass == 0)
            for (size_t m = 0; m < cells; ++m) cell_start[m + 1] += cell_start[m];
        else
            for (size_t m = cells; m > 0; --m) cell_start[m] = cell_start[m - 1];
    }
    cell_start[0] = 0;
    /* Each candidate pair is tested in one cell only: the cell holding the lower corner of the
     * overlap of the two boxes. Triangles are in increasing order within a cell. */
    for (size_t m = 0; m < cells; ++m) {
        for (uint32_t i = cell_start[m]; i < cell_start[m + 1]; ++i) {
            uint32_t ta = cell_tri[i];
            const float* ba = box + 6 * (size_t)ta;
            const uint32_t* ia = indices.ptr + 3 * (size_t)ta;
            uint32_t wa[3] = {weld[ia[0]], weld[ia[1]], weld[ia[2]]};
            dvec3 A[3] = {to_d(positions.ptr[ia[0]]), to_d(positions.ptr[ia[1]]), to_d(positions.ptr[ia[2]])};
            int axA = -2;
            for (uint32_t j = i + 1; j < cell_start[m + 1]; ++j) {
                uint32_t tb = cell_tri[j];
                const float* bb = box + 6 * (size_t)tb;
                if (ba[0] > bb[3] || bb[0] > ba[3] || ba[1] > bb[4] || bb[1] > ba[4] || ba[2] > bb[5] ||
                    bb[2] > ba[5])
                    continue;
                const uint32_t* ca = tri_cell + 6 * (size_t)ta;
                const uint32_t* cb = tri_cell + 6 * (size_t)tb;
                size_t own = AKP_CELL_ID(ca[0] > cb[0] ? ca[0] : cb[0], ca[1] > cb[1] ? ca[1] : cb[1],
                                         ca[2] > cb[2] ? ca[2] : cb[2]);
                if (own != m) continue;
                const uint32_t* ib = indices.ptr + 3 * (size_t)tb;
                bool shared = false;
                for (int p = 0; p < 3; ++p)
                    for (int q = 0; q < 3; ++q) shared = shared || wa[p] == weld[ib[q]];
                if (shared) continue;
                if (axA == -2) axA = dominant_axis(A[0], A[1], A[2]);
                dvec3 B[3] = {to_d(positions.ptr[ib[0]]), to_d(positions.ptr[ib[1]]), to_d(positions.ptr[ib[2]])};
                if (!tri_tri(A, axA, B, dominant_axis(B[0], B[1], B[2]))) continue;
                ++count;
                if (written + 2 <= out_pairs.count) {
                    out_pairs.ptr[written++] = ta < tb ? ta : tb;
                    out_pairs.ptr[written++] = ta < tb ? tb : ta;
                }
            }
        }
    }
#undef AKP_CELL_ID
    free(cell_start), free(cell_tri);
done:
    free(weld), free(box), free(tri_cell);
    *out_count = count;
    return res;
}
