/* Blend shapes: dense and sparse differential blending, the full form, and built sets.
 *
 * The hot loop is "out += w * delta" over 3V floats. Dense targets are applied in blocks of
 * vertices small enough for the output block to stay in L1 while up to four targets stream
 * through it at once (one load/store of the output per four targets). Sparse targets scatter
 * into the finished output afterwards. SSE2 is used when the compiler advertises it and
 * AK_NO_SIMD is not defined; the scalar loops are the reference and give the same sums up to
 * rounding order. */
#include <animkit/blendshape.h>

#include "internal.h"

#if !defined(AK_NO_SIMD) && (defined(__SSE2__) || defined(_M_X64) || defined(_M_AMD64))
#define BS_SSE2 1
#include <emmintrin.h>
#else
#define BS_SSE2 0
#endif

/* ---- private types ------------------------------------------------------------------------ */

typedef struct bs_target {
    size_t moved_count;           /* kept vertices; vertex_count when dense */
    const uint32_t* indices;      /* [moved_count] ascending, or NULL when dense */
    const ak_vec3* deltas;        /* [moved_count] (sparse) or [vertex_count] (dense) */
    const ak_vec3* normal_deltas; /* same length, or NULL */
} bs_target;

struct ak_blendshape_set {
    ak_allocator alloc;
    size_t vertex_count;
    size_t target_count;
    size_t memory_size;
    bool has_normals;
    bs_target* targets; /* [target_count] */
};

/* Where the dense deltas of target k live: either a target-major array (stride 3V floats) or
 * a set's per-target pointers (sparse targets skipped). */
typedef struct bs_source {
    const float* base;         /* target-major deltas, or NULL when targets is used */
    size_t stride;             /* floats between targets */
    const bs_target* targets;  /* set targets, or NULL */
    bool normals;              /* use the set's normal deltas */
} bs_source;

/* Floats per block: 3 * 1024 vertices = 12 KiB of output, stays in L1 next to 4 streams. */
#define BS_BLOCK 3072u

/* ---- kernels -------------------------------------------------------------------------------- */

static void madd1(float* restrict out, const float* restrict d, float w, size_t n) {
    size_t i = 0;
#if BS_SSE2
    const __m128 vw = _mm_set1_ps(w);
    for (; i + 8 <= n; i += 8) {
        __m128 a = _mm_loadu_ps(out + i), b = _mm_loadu_ps(out + i + 4);
        a = _mm_add_ps(a, _mm_mul_ps(vw, _mm_loadu_ps(d + i)));
        b = _mm_add_ps(b, _mm_mul_ps(vw, _mm_loadu_ps(d + i + 4)));
        _mm_storeu_ps(out + i, a);
        _mm_storeu_ps(out + i + 4, b);
    }
#endif
    for (; i < n; ++i) out[i] += w * d[i];
}

static void madd4(float* restrict out, const float* restrict d0, const float* restrict d1,
                  const float* restrict d2, const float* restrict d3, const float w[4], size_t n) {
    size_t i = 0;
#if BS_SSE2
    const __m128 w0 = _mm_set1_ps(w[0]), w1 = _mm_set1_ps(w[1]);
    const __m128 w2 = _mm_set1_ps(w[2]), w3 = _mm_set1_ps(w[3]);
    for (; i + 4 <= n; i += 4) {
        __m128 s01 = _mm_add_ps(_mm_mul_ps(w0, _mm_loadu_ps(d0 + i)), _mm_mul_ps(w1, _mm_loadu_ps(d1 + i)));
        __m128 s23 = _mm_add_ps(_mm_mul_ps(w2, _mm_loadu_ps(d2 + i)), _mm_mul_ps(w3, _mm_loadu_ps(d3 + i)));
        _mm_storeu_ps(out + i, _mm_add_ps(_mm_loadu_ps(out + i), _mm_add_ps(s01, s23)));
    }
#endif
    for (; i < n; ++i) out[i] += (w[0] * d0[i] + w[1] * d1[i]) + (w[2] * d2[i] + w[3] * d3[i]);
}

static const float* source_ptr(const bs_source* s, size_t k) {
    if (!s->targets) return s->base + k * s->stride;
    const bs_target* t = &s->targets[k];
    if (t->indices) return NULL; /* sparse: handled by scatter */
    return (const float*)(s->normals ? t->normal_deltas : t->deltas);
}

/* out[0, n3) = (base or 0) + sum over dense targets with non-zero weight. out may equal base. */
static void blend_dense(float* out, const float* base, const bs_source* src, const float* w, size_t k_count,
                        size_t n3) {
    for (size_t lo = 0; lo < n3; lo += BS_BLOCK) {
        size_t n = n3 - lo < BS_BLOCK ? n3 - lo : BS_BLOCK;
        float* o = out + lo;
        if (!base) memset(o, 0, n * sizeof(float));
        else if (base != out) memcpy(o, base + lo, n * sizeof(float));
        const float* p[4];
        float pw[4];
        int g = 0;
        for (size_t k = 0; k < k_count; ++k) {
            if (w[k] == 0.0f) continue;
            const float* d = source_ptr(src, k);
            if (!d) continue;
            p[g] = d + lo;
            pw[g] = w[k];
            if (++g == 4) {
                madd4(o, p[0], p[1], p[2], p[3], pw, n);
                g = 0;
            }
        }
        for (int j = 0; j < g; ++j) madd1(o, p[j], pw[j], n);
    }
}

static void blend_sparse(ak_vec3* out, const ak_blendshape_set* set, const float* w, bool normals) {
    for (size_t k = 0; k < set->target_count; ++k) {
        const bs_target* t = &set->targets[k];
        if (!t->indices || w[k] == 0.0f) continue;
        const ak_vec3* d = normals ? t->normal_deltas : t->deltas;
        const float wk = w[k];
        for (size_t j = 0; j < t->moved_count; ++j) {
            ak_vec3* o = &out[t->indices[j]];
            o->x += wk * d[j].x;
            o->y += wk * d[j].y;
            o->z += wk * d[j].z;
        }
    }
}

static void renormalize(ak_vec3* n, size_t count) {
    size_t i = 0;
#if BS_SSE2
    /* Four square roots and divisions at a time; the dot products and the scaling stay scalar
     * (the array is xyz-interleaved). */
    const __m128 tiny = _mm_set1_ps(1e-24f), huge = _mm_set1_ps(3.0e38f), one = _mm_set1_ps(1.0f);
    for (; i + 4 <= count; i += 4) {
        float l2[4], s[4];
        for (unsigned q = 0; q < 4; ++q) {
            const ak_vec3 v = n[i + q];
            l2[q] = v.x * v.x + v.y * v.y + v.z * v.z;
        }
        const __m128 l = _mm_loadu_ps(l2);
        const unsigned ok = (unsigned)_mm_movemask_ps(_mm_and_ps(_mm_cmpgt_ps(l, tiny), _mm_cmplt_ps(l, huge)));
        _mm_storeu_ps(s, _mm_div_ps(one, _mm_sqrt_ps(_mm_max_ps(l, tiny))));
        for (unsigned q = 0; q < 4; ++q) {
            ak_vec3* v = &n[i + q];
            if (ok & (1u << q)) {
                v->x *= s[q];
                v->y *= s[q];
                v->z *= s[q];
            } else {
                *v = ak_vec3_make(0.0f, 1.0f, 0.0f);
            }
        }
    }
#endif
    for (; i < count; ++i) {
        const float l2 = n[i].x * n[i].x + n[i].y * n[i].y + n[i].z * n[i].z;
        if (l2 > 1e-24f && l2 < 3.0e38f) {
            const float s = 1.0f / sqrtf(l2);
            n[i].x *= s;
            n[i].y *= s;
            n[i].z *= s;
        } else {
            n[i] = ak_vec3_make(0.0f, 1.0f, 0.0f);
        }
    }
}

static ak_result check_weights(ak_f32_cspan w) {
    for (size_t k = 0; k < w.count; ++k)
        if (!ak_finitef(w.ptr[k])) return AK_ERR_BAD_DATA;
    return AK_OK;
}

/* ---- dense jobs ------------------------------------------------------------------------------ */

ak_result ak_blendshape_dense_validate(const ak_blendshape_dense_job* job) {
    if (!job) return AK_ERR_NULL_ARG;
    const size_t k = job->weights.count, v = job->base_positions.count;
    if (k > 0 && !job->weights.ptr) return AK_ERR_NULL_ARG;
    if (!job->base_positions.ptr || v == 0 || !job->out_positions.ptr) return AK_ERR_NULL_ARG;
    if (k > 0 && !job->deltas.ptr) return AK_ERR_NULL_ARG;
    if (job->out_normals.ptr && !job->base_normals.ptr) return AK_ERR_NULL_ARG;
    if (k > 0 && job->deltas.count / k != v) return AK_ERR_BAD_ARG;
    if (job->deltas.count != k * v) return AK_ERR_BAD_ARG;
    if (job->base_normals.ptr && job->base_normals.count != v) return AK_ERR_BAD_ARG;
    if (job->normal_deltas.ptr && job->normal_deltas.count != k * v) return AK_ERR_BAD_ARG;
    if (job->out_positions.count < v) return AK_ERR_SPAN_SMALL;
    if (job->out_normals.ptr && job->out_normals.count < v) return AK_ERR_SPAN_SMALL;
    return check_weights(job->weights);
}

ak_result ak_blendshape_dense_run(const ak_blendshape_dense_job* job) {
    ak_result r = ak_blendshape_dense_validate(job);
    if (r != AK_OK) return r;
    const size_t k = job->weights.count, v = job->base_positions.count;
    bs_source src = {(const float*)job->deltas.ptr, 3 * v, NULL, false};
    blend_dense((float*)job->out_positions.ptr, (const float*)job->base_positions.ptr, &src, job->weights.ptr, k,
                3 * v);
    if (job->out_normals.ptr) {
        if (job->normal_deltas.ptr) {
            bs_source ns = {(const float*)job->normal_deltas.ptr, 3 * v, NULL, false};
            blend_dense((float*)job->out_normals.ptr, (const float*)job->base_normals.ptr, &ns, job->weights.ptr, k,
                        3 * v);
        } else if (job->out_normals.ptr != job->base_normals.ptr) {
            memcpy(job->out_normals.ptr, job->base_normals.ptr, v * sizeof(ak_vec3));
        }
        renormalize(job->out_normals.ptr, v);
    }
    return AK_OK;
}

ak_result ak_blendshape_full_validate(const ak_blendshape_full_job* job) {
    if (!job) return AK_ERR_NULL_ARG;
    const size_t k = job->weights.count;
    if (!job->weights.ptr || k == 0 || !job->shapes.ptr || job->shapes.count == 0 || !job->out_positions.ptr)
        return AK_ERR_NULL_ARG;
    if (job->out_normals.ptr && !job->shape_normals.ptr) return AK_ERR_NULL_ARG;
    if (job->shapes.count % k != 0) return AK_ERR_BAD_ARG;
    if (job->shape_normals.ptr && job->shape_normals.count != job->shapes.count) return AK_ERR_BAD_ARG;
    const size_t v = job->shapes.count / k;
    if (job->out_positions.count < v) return AK_ERR_SPAN_SMALL;
    if (job->out_normals.ptr && job->out_normals.count < v) return AK_ERR_SPAN_SMALL;
    return check_weights(job->weights);
}

ak_result ak_blendshape_full_run(const ak_blendshape_full_job* job) {
    ak_result r = ak_blendshape_full_validate(job);
    if (r != AK_OK) return r;
    const size_t k = job->weights.count, v = job->shapes.count / k;
    bs_source src = {(const float*)job->shapes.ptr, 3 * v, NULL, false};
    blend_dense((float*)job->out_positions.ptr, NULL, &src, job->weights.ptr, k, 3 * v);
    if (job->out_normals.ptr) {
        bs_source ns = {(const float*)job->shape_normals.ptr, 3 * v, NULL, false};
        blend_dense((float*)job->out_normals.ptr, NULL, &ns, job->weights.ptr, k, 3 * v);
        renormalize(job->out_normals.ptr, v);
    }
    return AK_OK;
}

ak_result ak_blendshape_deltas_from_shapes(ak_vec3_cspan base, ak_vec3_cspan shapes, ak_vec3_span out_deltas) {
    if (!base.ptr || base.count == 0 || !shapes.ptr || !out_deltas.ptr) return AK_ERR_NULL_ARG;
    if (shapes.count % base.count != 0) return AK_ERR_BAD_ARG;
    if (out_deltas.count < shapes.count) return AK_ERR_SPAN_SMALL;
    const size_t v = base.count;
    for (size_t i = 0; i < shapes.count; ++i) out_deltas.ptr[i] = ak_vec3_sub(shapes.ptr[i], base.ptr[i % v]);
    return AK_OK;
}

bool ak_blendshape_deltas_are_finite(ak_vec3_cspan deltas) {
    if (!deltas.ptr) return true;
    const float* f = (const float*)deltas.ptr;
    /* x - x is 0 for finite x and NaN otherwise; summing keeps the loop branch-free. */
    float acc = 0.0f;
    for (size_t i = 0; i < 3 * deltas.count; ++i) acc += f[i] - f[i];
    return acc == 0.0f;
}

/* ---- mesh job --------------------------------------------------------------------------------- */

static void mesh_to_dense(const ak_blendshape_mesh_job* job, ak_blendshape_dense_job* d) {
    const ak_mesh* m = job->mesh;
    const size_t v = m->vertex_count, k = m->morph_target_count;
    memset(d, 0, sizeof(*d));
    d->weights = job->weights.ptr ? job->weights : (ak_f32_cspan){m->morph_weights, m->morph_weights ? k : 0};
    d->base_positions = (ak_vec3_cspan){m->positions, v};
    d->deltas = (ak_vec3_cspan){m->morph_positions, m->morph_positions ? k * v : 0};
    d->base_normals = (ak_vec3_cspan){m->normals, m->normals ? v : 0};
    d->normal_deltas = (ak_vec3_cspan){m->morph_normals, m->morph_normals ? k * v : 0};
    d->out_positions = job->out_positions;
    d->out_normals = job->out_normals;
}

ak_result ak_blendshape_mesh_validate(const ak_blendshape_mesh_job* job) {
    if (!job || !job->mesh || !job->out_positions.ptr) return AK_ERR_NULL_ARG;
    const ak_mesh* m = job->mesh;
    const size_t k = m->morph_target_count;
    if (!m->positions || m->vertex_count == 0) return AK_ERR_NULL_ARG;
    if (k > 0 && !m->morph_positions) return AK_ERR_NULL_ARG;
    if (job->out_normals.ptr && !m->normals) return AK_ERR_NULL_ARG;
    if (job->weights.ptr ? job->weights.count != k : (k > 0 && !m->morph_weights)) {
        return job->weights.ptr ? AK_ERR_BAD_ARG : AK_ERR_NULL_ARG;
    }
    ak_blendshape_dense_job d;
    mesh_to_dense(job, &d);
    return ak_blendshape_dense_validate(&d);
}

ak_result ak_blendshape_mesh_run(const ak_blendshape_mesh_job* job) {
    ak_result r = ak_blendshape_mesh_validate(job);
    if (r != AK_OK) return r;
    ak_blendshape_dense_job d;
    mesh_to_dense(job, &d);
    return ak_blendshape_dense_run(&d);
}

/* ---- sets ------------------------------------------------------------------------------------- */

ak_blendshape_set_desc ak_blendshape_set_desc_from_mesh(const ak_mesh* mesh) {
    ak_blendshape_set_desc d;
    memset(&d, 0, sizeof(d));
    if (!mesh) return d;
    d.vertex_count = mesh->vertex_count;
    d.target_count = mesh->morph_target_count;
    if (mesh->morph_positions) d.deltas = (ak_vec3_cspan){mesh->morph_positions, d.vertex_count * d.target_count};
    if (mesh->morph_normals) d.normal_deltas = (ak_vec3_cspan){mesh->morph_normals, d.vertex_count * d.target_count};
    return d;
}

static bool delta_kept(const ak_vec3* d, const ak_vec3* n, size_t i, float t2) {
    if (ak_vec3_length_sq(d[i]) > t2) return true;
    return n && ak_vec3_length_sq(n[i]) > t2;
}

ak_result ak_blendshape_set_create(const ak_blendshape_set_desc* desc, const ak_allocator* alloc,
                                   ak_blendshape_set** out_set) {
    if (out_set) *out_set = NULL;
    if (!desc || !out_set || !desc->deltas.ptr) return AK_ERR_NULL_ARG;
    const size_t v = desc->vertex_count, k = desc->target_count;
    if (v == 0 || k == 0) return AK_ERR_EMPTY;
    if (v > UINT32_MAX || k > SIZE_MAX / v || k * v > SIZE_MAX / (2 * sizeof(ak_vec3) + sizeof(uint32_t)))
        return AK_ERR_BAD_ARG;
    if (desc->deltas.count != k * v) return AK_ERR_BAD_ARG;
    const bool has_n = desc->normal_deltas.ptr != NULL;
    if (has_n && desc->normal_deltas.count != k * v) return AK_ERR_BAD_ARG;
    if (!(desc->threshold >= 0.0f) || !ak_finitef(desc->threshold)) return AK_ERR_BAD_ARG;
    if ((unsigned)desc->storage >= (unsigned)AK_BLENDSHAPE_STORAGE_COUNT) return AK_ERR_BAD_ARG;
    if (!ak_blendshape_deltas_are_finite(desc->deltas) || !ak_blendshape_deltas_are_finite(desc->normal_deltas))
        return AK_ERR_BAD_DATA;

    const float t2 = desc->threshold * desc->threshold;
    const ak_vec3* nd = has_n ? desc->normal_deltas.ptr : NULL;
    /* Pass 1: count kept vertices per target and size the single allocation. */
    size_t size = akp_align16(sizeof(ak_blendshape_set)) + akp_align16(k * sizeof(bs_target));
    for (size_t t = 0; t < k; ++t) {
        const ak_vec3* d = desc->deltas.ptr + t * v;
        const ak_vec3* n = nd ? nd + t * v : NULL;
        size_t moved = 0;
        for (size_t i = 0; i < v; ++i) moved += delta_kept(d, n, i, t2);
        bool sparse = desc->storage == AK_BLENDSHAPE_STORAGE_SPARSE ||
                      (desc->storage == AK_BLENDSHAPE_STORAGE_AUTO && moved * 3 <= v);
        size_t rows = sparse ? moved : v;
        if (sparse) size += akp_align16(rows * sizeof(uint32_t));
        size += akp_align16(rows * sizeof(ak_vec3)) * (has_n ? 2u : 1u);
    }
    unsigned char* mem = (unsigned char*)akp_alloc(alloc, size);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_blendshape_set* set = (ak_blendshape_set*)mem;
    memset(set, 0, sizeof(*set));
    if (alloc) set->alloc = *alloc;
    set->vertex_count = v;
    set->target_count = k;
    set->memory_size = size;
    set->has_normals = has_n;
    size_t off = akp_align16(sizeof(ak_blendshape_set));
    set->targets = (bs_target*)(mem + off);
    off += akp_align16(k * sizeof(bs_target));

    /* Pass 2: copy the kept deltas (dense targets get zeros where deltas were dropped). */
    for (size_t t = 0; t < k; ++t) {
        const ak_vec3* d = desc->deltas.ptr + t * v;
        const ak_vec3* n = nd ? nd + t * v : NULL;
        size_t moved = 0;
        for (size_t i = 0; i < v; ++i) moved += delta_kept(d, n, i, t2);
        bool sparse = desc->storage == AK_BLENDSHAPE_STORAGE_SPARSE ||
                      (desc->storage == AK_BLENDSHAPE_STORAGE_AUTO && moved * 3 <= v);
        bs_target* tg = &set->targets[t];
        size_t rows = sparse ? moved : v;
        uint32_t* idx = NULL;
        if (sparse) {
            idx = (uint32_t*)(mem + off);
            off += akp_align16(rows * sizeof(uint32_t));
        }
        ak_vec3* dd = (ak_vec3*)(mem + off);
        off += akp_align16(rows * sizeof(ak_vec3));
        ak_vec3* dn = NULL;
        if (has_n) {
            dn = (ak_vec3*)(mem + off);
            off += akp_align16(rows * sizeof(ak_vec3));
        }
        size_t j = 0;
        for (size_t i = 0; i < v; ++i) {
            bool keep = delta_kept(d, n, i, t2);
            if (sparse) {
                if (!keep) continue;
                idx[j] = (uint32_t)i;
                dd[j] = d[i];
                if (dn) dn[j] = n[i];
                ++j;
            } else {
                dd[i] = keep ? d[i] : ak_vec3_zero();
                if (dn) dn[i] = keep ? n[i] : ak_vec3_zero();
            }
        }
        tg->moved_count = sparse ? moved : v;
        tg->indices = idx;
        tg->deltas = dd;
        tg->normal_deltas = dn;
    }
    AK_ASSERT(off == size);
    *out_set = set;
    return AK_OK;
}

void ak_blendshape_set_destroy(ak_blendshape_set* set) {
    if (!set) return;
    ak_allocator a = set->alloc;
    akp_free(&a, set);
}

size_t ak_blendshape_set_vertex_count(const ak_blendshape_set* set) { return set ? set->vertex_count : 0; }
size_t ak_blendshape_set_target_count(const ak_blendshape_set* set) { return set ? set->target_count : 0; }
bool ak_blendshape_set_has_normals(const ak_blendshape_set* set) { return set ? set->has_normals : false; }

size_t ak_blendshape_set_moved_count(const ak_blendshape_set* set, size_t target_index) {
    if (!set || target_index >= set->target_count) return 0;
    return set->targets[target_index].moved_count;
}

bool ak_blendshape_set_target_is_sparse(const ak_blendshape_set* set, size_t target_index) {
    if (!set || target_index >= set->target_count) return false;
    return set->targets[target_index].indices != NULL;
}

size_t ak_blendshape_set_memory_size(const ak_blendshape_set* set) { return set ? set->memory_size : 0; }

ak_result ak_blendshape_validate(const ak_blendshape_job* job) {
    if (!job || !job->set) return AK_ERR_NULL_ARG;
    const ak_blendshape_set* s = job->set;
    if (!job->weights.ptr || !job->base_positions.ptr || !job->out_positions.ptr) return AK_ERR_NULL_ARG;
    if (job->out_normals.ptr && !job->base_normals.ptr) return AK_ERR_NULL_ARG;
    if (job->weights.count != s->target_count) return AK_ERR_BAD_ARG;
    if (job->base_positions.count != s->vertex_count) return AK_ERR_BAD_ARG;
    if (job->base_normals.ptr && job->base_normals.count != s->vertex_count) return AK_ERR_BAD_ARG;
    if (job->out_positions.count < s->vertex_count) return AK_ERR_SPAN_SMALL;
    if (job->out_normals.ptr && job->out_normals.count < s->vertex_count) return AK_ERR_SPAN_SMALL;
    return check_weights(job->weights);
}

ak_result ak_blendshape_run(const ak_blendshape_job* job) {
    ak_result r = ak_blendshape_validate(job);
    if (r != AK_OK) return r;
    const ak_blendshape_set* s = job->set;
    const size_t v = s->vertex_count, k = s->target_count;
    const float* w = job->weights.ptr;
    bs_source src = {NULL, 0, s->targets, false};
    blend_dense((float*)job->out_positions.ptr, (const float*)job->base_positions.ptr, &src, w, k, 3 * v);
    blend_sparse(job->out_positions.ptr, s, w, false);
    if (job->out_normals.ptr) {
        if (s->has_normals) {
            bs_source ns = {NULL, 0, s->targets, true};
            blend_dense((float*)job->out_normals.ptr, (const float*)job->base_normals.ptr, &ns, w, k, 3 * v);
            blend_sparse(job->out_normals.ptr, s, w, true);
        } else if (job->out_normals.ptr != job->base_normals.ptr) {
            memcpy(job->out_normals.ptr, job->base_normals.ptr, v * sizeof(ak_vec3));
        }
        renormalize(job->out_normals.ptr, v);
    }
    return AK_OK;
}
