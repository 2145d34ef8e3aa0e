/* Triangle mesh container and geometric queries (bounds, normals, volume, closedness,
 * skin-weight validation and clean-up). */
#include <animkit/mesh.h>

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
    if (idx_count > 0 && (uint64_t)v > (uint64_t)UINT32_MAX + 1u) return AK_ERR_BAD_ARG; /* indices are u32 (64-bit sum: size_t may be 32 bits) */

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
    /* rep[v]: the first vertex at v's position (open addressing, linear probing) */
    uint32_t* rep = scratch.ptr;
    uint32_t* table = scratch.ptr + n;
    const size_t T = need - n, mask = T - 1;
    for (size_t k = 0; k < T; ++k) table[k] = UINT32_MAX;
    for (size_t v = 0; v < n; ++v) {
        ak_vec3 p = positions.ptr[v];
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
            if (same_position(positions.ptr[table[k]], p)) {
                rep[v] = table[k];
                break;
            }
        }
    }
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
