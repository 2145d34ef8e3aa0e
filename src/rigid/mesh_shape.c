/* Static heightfields and triangle meshes for the rigid module: validation, the copy into the
 * model and, for a triangle mesh, a bounding volume hierarchy (object-median splits along the
 * longest axis of the triangles' centroids, leaves of at most 4 triangles, so its depth is at
 * most log2(triangles) + 2). */
#include <math.h>
#include <string.h>

#include "rigid_impl.h"

#define LEAF_SIZE 4u

static size_t align16(size_t s) { return (s + 15) & ~(size_t)15; }

ak_result akp_rigid_mesh_check(const ak_rigid_shape* s) {
    if (s->type == AK_RIGID_HEIGHTFIELD) {
        if (s->rows < 2 || s->cols < 2) return AK_ERR_BAD_ARG;
        if ((uint64_t)s->rows * s->cols > AK_RIGID_HEIGHTFIELD_MAX_SAMPLES) return AK_ERR_BAD_ARG;
        if (!ak_finitef(s->spacing)) return AK_ERR_BAD_DATA;
        if (!(s->spacing > 0.0f)) return AK_ERR_BAD_ARG;
        if (s->heights.count != (size_t)s->rows * s->cols) return AK_ERR_BAD_ARG;
        if (!s->heights.ptr) return AK_ERR_NULL_ARG;
        for (size_t i = 0; i < s->heights.count; ++i)
            if (!ak_finitef(s->heights.ptr[i])) return AK_ERR_BAD_DATA;
        return AK_OK;
    }
    size_t ni = s->indices.count, nv = s->vertices.count;
    if (ni == 0 || ni % 3 || ni / 3 > AK_RIGID_TRIMESH_MAX_TRIANGLES || nv == 0 ||
        nv > 3 * (size_t)AK_RIGID_TRIMESH_MAX_TRIANGLES)
        return AK_ERR_BAD_ARG;
    if (!s->indices.ptr || !s->vertices.ptr) return AK_ERR_NULL_ARG;
    for (size_t i = 0; i < nv; ++i)
        if (!ak_vec3_is_finite(s->vertices.ptr[i])) return AK_ERR_BAD_DATA;
    for (size_t i = 0; i < ni; ++i)
        if (s->indices.ptr[i] >= nv) return AK_ERR_BAD_INDEX;
    return AK_OK;
}

static size_t node_cap(size_t nt) { return 2 * nt + 1; }

size_t akp_rigid_mesh_size(const ak_rigid_shape* s) {
    size_t head = align16(sizeof(akp_mesh));
    if (s->type == AK_RIGID_HEIGHTFIELD) return head + align16(s->heights.count * sizeof(float));
    size_t nt = s->indices.count / 3;
    return head + align16(s->vertices.count * sizeof(ak_vec3)) +
           align16(s->indices.count * sizeof(uint32_t)) + align16(node_cap(nt) * sizeof(akp_bvh_node)) +
           align16(nt * sizeof(uint32_t));
}

size_t akp_rigid_mesh_scratch_size(const ak_rigid_shape* s) {
    if (s->type == AK_RIGID_HEIGHTFIELD) return 0;
    return align16(s->indices.count / 3 * sizeof(ak_vec3)) + 64 * sizeof(uint32_t) * 3;
}

/* Rearrange order[lo, hi) so that the k-th smallest key (the centroids' axis coordinate) is at
 * k, no larger one before it and no smaller one after (quickselect with a three-way partition,
 * so runs of equal keys, common in grids, cost no more than distinct ones). */
static void select_kth(uint32_t* order, const ak_vec3* cen, int axis, uint32_t lo, uint32_t hi,
                       uint32_t k) {
#define KEY(i) (axis == 0 ? cen[order[i]].x : (axis == 1 ? cen[order[i]].y : cen[order[i]].z))
    while (hi - lo > 1) {
        float pivot = KEY(lo + (hi - lo) / 2);
        uint32_t lt = lo, i = lo, gt = hi; /* [lo, lt) <, [lt, i) ==, [gt, hi) > */
        while (i < gt) {
            float key = KEY(i);
            uint32_t t = order[i];
            if (key < pivot) {
                order[i++] = order[lt];
                order[lt++] = t;
            } else if (key > pivot) {
                order[i] = order[--gt];
                order[gt] = t;
            } else {
                ++i;
            }
        }
        if (k < lt)
            hi = lt;
        else if (k >= gt)
            lo = gt;
        else
            return;
    }
#undef KEY
}

akp_mesh* akp_rigid_mesh_build(const ak_rigid_shape* s, void* mem, void* scratch) {
    unsigned char* p = mem;
    akp_mesh* m = (akp_mesh*)p;
    memset(m, 0, sizeof *m);
    p += align16(sizeof(akp_mesh));
    if (s->type == AK_RIGID_HEIGHTFIELD) {
        float* h = (float*)p;
        memcpy(h, s->heights.ptr, s->heights.count * sizeof(float));
        m->is_heightfield = true;
        m->heights = h;
        m->rows = s->rows;
        m->cols = s->cols;
        m->spacing = s->spacing;
        float lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < s->heights.count; ++i) lo = ak_minf(lo, h[i]), hi = ak_maxf(hi, h[i]);
        m->min_height = lo;
        m->max_height = hi;
        float ex = s->spacing * (float)(s->cols - 1), ez = s->spacing * (float)(s->rows - 1);
        float ey = ak_maxf(fabsf(lo), fabsf(hi));
        m->bound_radius = sqrtf(ex * ex + ey * ey + ez * ez);
        return m;
    }
    size_t nv = s->vertices.count, ni = s->indices.count, nt = ni / 3;
    ak_vec3* v = (ak_vec3*)p;
    p += align16(nv * sizeof(ak_vec3));
    uint32_t* tris = (uint32_t*)p;
    p += align16(ni * sizeof(uint32_t));
    akp_bvh_node* nodes = (akp_bvh_node*)p;
    p += align16(node_cap(nt) * sizeof(akp_bvh_node));
    uint32_t* order = (uint32_t*)p;
    memcpy(v, s->vertices.ptr, nv * sizeof(ak_vec3));
    memcpy(tris, s->indices.ptr, ni * sizeof(uint32_t));
    float br = 0.0f;
    for (size_t i = 0; i < nv; ++i) br = ak_maxf(br, ak_vec3_length(v[i]));
    ak_vec3* cen = (ak_vec3*)scratch;
    for (size_t t = 0; t < nt; ++t) {
        order[t] = (uint32_t)t;
        cen[t] = ak_vec3_scale(
            ak_vec3_add(ak_vec3_add(v[tris[3 * t]], v[tris[3 * t + 1]]), v[tris[3 * t + 2]]),
            1.0f / 3.0f);
    }
    /* nodes are split breadth-first: node k covers order[first, first + count) while pending */
    uint32_t nn = 1;
    nodes[0].first = 0;
    nodes[0].count = (uint32_t)nt;
    for (uint32_t k = 0; k < nn; ++k) {
        akp_bvh_node* nd = &nodes[k];
        ak_vec3 lo = ak_vec3_make(INFINITY, INFINITY, INFINITY), hi = ak_vec3_neg(lo);
        ak_vec3 clo = lo, chi = hi;
        for (uint32_t i = nd->first; i < nd->first + nd->count; ++i) {
            uint32_t t = order[i];
            for (int c = 0; c < 3; ++c) {
                ak_vec3 q = v[tris[3 * t + (uint32_t)c]];
                lo = ak_vec3_min(lo, q);
                hi = ak_vec3_max(hi, q);
            }
            clo = ak_vec3_min(clo, cen[t]);
            chi = ak_vec3_max(chi, cen[t]);
        }
        nd->lo = lo;
        nd->hi = hi;
        if (nd->count <= LEAF_SIZE) continue;
        ak_vec3 ext = ak_vec3_sub(chi, clo);
        int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
        uint32_t first = nd->first, count = nd->count, half = count / 2;
        select_kth(order, cen, axis, first, first + count, first + half);
        nodes[nn] = (akp_bvh_node){lo, hi, first, half};
        nodes[nn + 1] = (akp_bvh_node){lo, hi, first + half, count - half};
        nd->first = nn;
        nd->count = 0;
        nn += 2;
    }
    m->verts = v;
    m->tris = tris;
    m->nv = (uint32_t)nv;
    m->nt = (uint32_t)nt;
    m->nodes = nodes;
    m->order = order;
    m->bound_radius = br;
    return m;
}
