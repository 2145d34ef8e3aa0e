/* Optimized centers of rotation (Le & Hodgins 2016, "Real-time skeletal skinning with
 * optimized centers of rotation"): the precomputation and its cache format.
 *
 * 1. Subdivide: each triangle is bisected at the edge whose end weights differ most (L2)
 *    until no edge differs by more than the threshold (at most MAX_DEPTH levels). Triangles
 *    are subdivided independently: the centers only integrate over the surface, so T-junctions
 *    between neighbours do not matter.
 * 2. Each sub-triangle keeps its area, centroid and mean corner weights (sparse).
 * 3. A vertex's center is the similarity-weighted mean of the centroids (weights s * area).
 *    The similarity is zero unless the triangle and the vertex both weigh some pair of joints,
 *    so the pruned version indexes sub-triangles by joint pair (sorted (pair, triangle) keys)
 *    and visits, per vertex, only the triangles listed under its own pairs (deduplicated with
 *    a per-thread stamp array). Vertices are split between threads in interleaved chunks.
 * 4. A center depends only on the weights of its vertex, so vertices with bitwise-equal weights
 *    (seams, symmetric rings) are computed once. The naive reference skips 3 and 4. */
#include "tasks.h" /* thread_count > 1 */

#include "weights_internal.h"

#define MAX_DEPTH 12
#define MAX_SUPPORT (3 * AK_MAX_INFLUENCES)

typedef struct sparse_w {
    uint16_t j[MAX_SUPPORT];
    float w[MAX_SUPPORT];
    uint32_t n;
} sparse_w;

typedef struct subtri {
    double cx, cy, cz, area;
    uint32_t wofs, wn; /* range in the weight pool */
} subtri;

typedef struct cor_state {
    const ak_allocator* alloc;
    subtri* tris;
    size_t tri_count, tri_cap;
    uint16_t* pool_j;
    float* pool_w;
    size_t pool_count, pool_cap;
    bool oom;
} cor_state;

static void* grow(const ak_allocator* a, void* old, size_t old_bytes, size_t new_bytes) {
    void* p = akp_alloc(a, new_bytes);
    if (!p) return NULL;
    if (old) memcpy(p, old, old_bytes);
    akp_free(a, old);
    return p;
}

/* Sum of sparse vectors a * sa + b * sb (joints kept sorted). */
static void sparse_mix(const sparse_w* a, float sa, const sparse_w* b, float sb, sparse_w* out) {
    uint32_t i = 0, k = 0, n = 0;
    sparse_w r;
    while ((i < a->n || k < b->n) && n < MAX_SUPPORT) {
        if (k >= b->n || (i < a->n && a->j[i] < b->j[k])) {
            r.j[n] = a->j[i];
            r.w[n++] = a->w[i++] * sa;
        } else if (i >= a->n || b->j[k] < a->j[i]) {
            r.j[n] = b->j[k];
            r.w[n++] = b->w[k++] * sb;
        } else {
            r.j[n] = a->j[i];
            r.w[n++] = a->w[i++] * sa + b->w[k++] * sb;
        }
    }
    r.n = n;
    *out = r;
}

static double sparse_dist2(const sparse_w* a, const sparse_w* b) {
    sparse_w d;
    sparse_mix(a, 1.0f, b, -1.0f, &d);
    double s = 0.0;
    for (uint32_t i = 0; i < d.n; ++i) s += (double)d.w[i] * d.w[i];
    return s;
}

static void emit(cor_state* st, const ak_vec3* p, const sparse_w* const* w) {
    if (st->oom) return;
    ak_vec3 cr = ak_vec3_cross(ak_vec3_sub(p[1], p[0]), ak_vec3_sub(p[2], p[0]));
    double area = 0.5 * ak_vec3_length(cr);
    if (!(area > 0.0)) return; /* zero area contributes nothing */
    sparse_w m, avg;
    sparse_mix(w[0], 1.0f, w[1], 1.0f, &m);
    sparse_mix(&m, 1.0f / 3.0f, w[2], 1.0f / 3.0f, &avg);
    uint32_t keep = 0;
    for (uint32_t i = 0; i < avg.n; ++i)
        if (avg.w[i] > 0.0f) keep++;
    if (st->tri_count == st->tri_cap) {
        size_t cap = st->tri_cap ? st->tri_cap * 2 : 1024;
        subtri* t = (subtri*)grow(st->alloc, st->tris, st->tri_cap * sizeof(subtri), cap * sizeof(subtri));
        if (!t) {
            st->oom = true;
            return;
        }
        st->tris = t;
        st->tri_cap = cap;
    }
    if (st->pool_count + keep > st->pool_cap) {
        size_t cap = st->pool_cap ? st->pool_cap * 2 : 4096;
        while (cap < st->pool_count + keep) cap *= 2;
        uint16_t* pj = (uint16_t*)grow(st->alloc, st->pool_j, st->pool_cap * sizeof(uint16_t), cap * sizeof(uint16_t));
        if (!pj) {
            st->oom = true;
            return;
        }
        st->pool_j = pj;
        float* pw = (float*)grow(st->alloc, st->pool_w, st->pool_cap * sizeof(float), cap * sizeof(float));
        if (!pw) {
            st->oom = true;
            return;
        }
        st->pool_w = pw;
        st->pool_cap = cap;
    }
    subtri* t = &st->tris[st->tri_count++];
    t->cx = ((double)p[0].x + p[1].x + p[2].x) / 3.0;
    t->cy = ((double)p[0].y + p[1].y + p[2].y) / 3.0;
    t->cz = ((double)p[0].z + p[1].z + p[2].z) / 3.0;
    t->area = area;
    t->wofs = (uint32_t)st->pool_count;
    t->wn = keep;
    for (uint32_t i = 0; i < avg.n; ++i)
        if (avg.w[i] > 0.0f) {
            st->pool_j[st->pool_count] = avg.j[i];
            st->pool_w[st->pool_count++] = avg.w[i];
        }
}

static void subdivide(cor_state* st, const ak_vec3* p, const sparse_w* const* w, double thr2, int depth) {
    double d[3];
    int worst = 0;
    for (int e = 0; e < 3; ++e) {
        d[e] = sparse_dist2(w[e], w[(e + 1) % 3]);
        if (d[e] > d[worst]) worst = e;
    }
    if (d[worst] <= thr2 || depth >= MAX_DEPTH) {
        emit(st, p, w);
        return;
    }
    int a = worst, b = (worst + 1) % 3, c = (worst + 2) % 3;
    ak_vec3 mid = ak_vec3_scale(ak_vec3_add(p[a], p[b]), 0.5f);
    sparse_w mw;
    sparse_mix(w[a], 0.5f, w[b], 0.5f, &mw);
    ak_vec3 p1[3] = {p[a], mid, p[c]}, p2[3] = {mid, p[b], p[c]};
    const sparse_w* w1[3] = {w[a], &mw, w[c]};
    const sparse_w* w2[3] = {&mw, w[b], w[c]};
    subdivide(st, p1, w1, thr2, depth + 1);
    subdivide(st, p2, w2, thr2, depth + 1);
}

/* Sparse weights of vertex v: duplicates merged, zeros dropped, sorted by joint. */
static void vertex_sparse(const ak_skin_cor_desc* d, size_t v, sparse_w* out) {
    const uint32_t k = d->influence_count;
    sparse_w s;
    s.n = 0;
    for (uint32_t e = 0; e < k; ++e) {
        float w = d->weights.ptr[v * k + e];
        uint16_t j = d->joints.ptr[v * k + e];
        if (!(w > 0.0f)) continue;
        uint32_t i = 0;
        while (i < s.n && s.j[i] < j) ++i;
        if (i < s.n && s.j[i] == j) {
            s.w[i] += w;
            continue;
        }
        for (uint32_t m = s.n; m > i; --m) {
            s.j[m] = s.j[m - 1];
            s.w[m] = s.w[m - 1];
        }
        s.j[i] = j;
        s.w[i] = w;
        s.n++;
    }
    *out = s;
}

/* s(w_t, w_v) = sum_{j != k} w_tj w_tk w_vj w_vk exp(-(w_tj w_vk - w_tk w_vj)^2 / sigma^2),
 * over the joints where both are nonzero; v is given as a dense lookup vdense[joint]. */
static double similarity(const uint16_t* tj, const float* tw, uint32_t tn, const float* vdense, double inv_s2) {
    float a[MAX_SUPPORT], b[MAX_SUPPORT];
    uint32_t m = 0;
    for (uint32_t i = 0; i < tn; ++i) {
        float wv = vdense[tj[i]];
        if (wv > 0.0f) {
            a[m] = tw[i];
            b[m++] = wv;
        }
    }
    double s = 0.0;
    for (uint32_t x = 0; x < m; ++x)
        for (uint32_t y = x + 1; y < m; ++y) {
            double dd = (double)a[x] * b[y] - (double)a[y] * b[x];
            /* expf: relative error ~1e-7, far below the float output; 3x cheaper than exp */
            s += (double)a[x] * a[y] * b[x] * b[y] * (double)expf((float)(-dd * dd * inv_s2));
        }
    return 2.0 * s; /* the (j, k) and (k, j) terms are equal */
}

typedef struct cor_job {
    const ak_skin_cor_desc* d;
    const cor_state* st;
    const uint64_t* keys; /* (pair << 32) | triangle, sorted; NULL for the naive loop */
    size_t key_count;
    size_t joint_count;
    uint32_t thread_index, thread_count;
    const uint32_t* rep; /* [n]: first vertex with bitwise the same weights (its center is shared) */
    float* vdense;     /* [joint_count] */
    uint32_t* stamp;   /* [tri_count] */
    ak_vec3* out;
} cor_job;

static size_t lower_bound(const uint64_t* keys, size_t n, uint64_t x) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (keys[mid] < x) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

#define CHUNK 32

static void* cor_worker(void* arg) {
    cor_job* jb = (cor_job*)arg;
    const ak_skin_cor_desc* d = jb->d;
    const cor_state* st = jb->st;
    const size_t n = d->positions.count;
    const double inv_s2 = 1.0 / ((double)d->sigma * d->sigma);
    uint32_t stamp_id = 0;
    for (size_t c0 = (size_t)jb->thread_index * CHUNK; c0 < n; c0 += (size_t)jb->thread_count * CHUNK) {
        size_t c1 = c0 + CHUNK < n ? c0 + CHUNK : n;
        for (size_t v = c0; v < c1; ++v) {
            jb->out[v] = d->positions.ptr[v];
            if (jb->rep[v] != v) continue; /* copied from its representative afterwards */
            sparse_w sv;
            vertex_sparse(d, v, &sv);
            if (sv.n < 2) continue; /* single influence: rigid, center unused */
            for (uint32_t i = 0; i < sv.n; ++i) jb->vdense[sv.j[i]] = sv.w[i];
            double num[3] = {0, 0, 0}, den = 0.0;
            if (!jb->keys) {
                for (size_t t = 0; t < st->tri_count; ++t) {
                    const subtri* tr = &st->tris[t];
                    double s = similarity(st->pool_j + tr->wofs, st->pool_w + tr->wofs, tr->wn, jb->vdense, inv_s2);
                    if (s == 0.0) continue;
                    s *= tr->area;
                    num[0] += s * tr->cx;
                    num[1] += s * tr->cy;
                    num[2] += s * tr->cz;
                    den += s;
                }
            } else {
                ++stamp_id;
                for (uint32_t x = 0; x < sv.n; ++x)
                    for (uint32_t y = x + 1; y < sv.n; ++y) {
                        uint64_t pair = ((uint64_t)sv.j[x] << 16) | sv.j[y];
                        size_t at = lower_bound(jb->keys, jb->key_count, pair << 32);
                        for (; at < jb->key_count && (jb->keys[at] >> 32) == pair; ++at) {
                            uint32_t t = (uint32_t)(jb->keys[at] & 0xFFFFFFFFu);
                            if (jb->stamp[t] == stamp_id) continue;
                            jb->stamp[t] = stamp_id;
                            const subtri* tr = &st->tris[t];
                            double s = similarity(st->pool_j + tr->wofs, st->pool_w + tr->wofs, tr->wn, jb->vdense,
                                                  inv_s2);
                            if (s == 0.0) continue;
                            s *= tr->area;
                            num[0] += s * tr->cx;
                            num[1] += s * tr->cy;
                            num[2] += s * tr->cz;
                            den += s;
                        }
                    }
            }
            for (uint32_t i = 0; i < sv.n; ++i) jb->vdense[sv.j[i]] = 0.0f;
            if (den > 1e-300)
                jb->out[v] = ak_vec3_make((float)(num[0] / den), (float)(num[1] / den), (float)(num[2] / den));
        }
    }
    return NULL;
}

typedef struct vkey {
    uint64_t hash;
    uint32_t v;
} vkey;

static int cmp_vkey(const void* a, const void* b) {
    const vkey *x = (const vkey*)a, *y = (const vkey*)b;
    if (x->hash != y->hash) return x->hash < y->hash ? -1 : 1;
    return x->v < y->v ? -1 : (x->v > y->v ? 1 : 0);
}

static bool same_weights(const sparse_w* a, const sparse_w* b) {
    if (a->n != b->n) return false;
    for (uint32_t i = 0; i < a->n; ++i)
        if (a->j[i] != b->j[i] || memcmp(&a->w[i], &b->w[i], sizeof(float)) != 0) return false;
    return true;
}

/* rep[v] = the smallest vertex whose sparse weights are bitwise equal to v's. A center depends
 * only on the vertex's weights, so such vertices (UV and normal seams, symmetric rings) share
 * one computation. */
static ak_result find_representatives(const ak_skin_cor_desc* d, const ak_allocator* alloc, uint32_t* rep) {
    const size_t n = d->positions.count;
    vkey* keys = (vkey*)akp_alloc(alloc, n * sizeof(vkey));
    if (!keys) return AK_ERR_NO_MEMORY;
    for (size_t v = 0; v < n; ++v) {
        sparse_w s;
        vertex_sparse(d, v, &s);
        uint64_t h = akp_fnv1a(0xcbf29ce484222325ull, s.j, s.n * sizeof(uint16_t));
        keys[v].hash = akp_fnv1a(h, s.w, s.n * sizeof(float));
        keys[v].v = (uint32_t)v;
    }
    qsort(keys, n, sizeof(vkey), cmp_vkey);
    for (size_t i = 0; i < n;) {
        size_t e = i + 1;
        while (e < n && keys[e].hash == keys[i].hash) ++e;
        /* within a hash group, compare exactly (collisions stay separate) */
        for (size_t a = i; a < e; ++a) {
            uint32_t va = keys[a].v;
            rep[va] = va;
            sparse_w sa;
            vertex_sparse(d, va, &sa);
            for (size_t b = i; b < a; ++b) {
                uint32_t vb = keys[b].v;
                if (rep[vb] != vb) continue;
                sparse_w sb;
                vertex_sparse(d, vb, &sb);
                if (same_weights(&sa, &sb)) {
                    rep[va] = vb; /* vb < va: keys are sorted by vertex within a hash */
                    break;
                }
            }
        }
        i = e;
    }
    akp_free(alloc, keys);
    return AK_OK;
}

static int cmp_u64(const void* a, const void* b) {
    uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* ---- public ------------------------------------------------------------------------------ */

ak_skin_cor_desc ak_skin_cor_desc_resolved(const ak_skin_cor_desc* desc) {
    ak_skin_cor_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.sigma == 0.0f) d.sigma = 0.1f;
    if (d.subdivision_threshold == 0.0f) d.subdivision_threshold = 0.1f;
    if (d.thread_count == 0) d.thread_count = 2;
    return d;
}

uint64_t ak_skin_cor_key(const ak_skin_cor_desc* desc) {
    if (!desc) return 0;
    ak_skin_cor_desc d = ak_skin_cor_desc_resolved(desc);
    uint64_t h = 0xcbf29ce484222325ull;
    const size_t n = d.positions.count, k = d.influence_count;
    if (d.positions.ptr) h = akp_fnv1a(h, d.positions.ptr, n * sizeof(ak_vec3));
    if (d.indices.ptr) h = akp_fnv1a(h, d.indices.ptr, d.indices.count * sizeof(uint32_t));
    if (d.joints.ptr) h = akp_fnv1a(h, d.joints.ptr, (d.joints.count < n * k ? d.joints.count : n * k) * 2u);
    if (d.weights.ptr) h = akp_fnv1a(h, d.weights.ptr, (d.weights.count < n * k ? d.weights.count : n * k) * 4u);
    uint32_t kk = d.influence_count;
    h = akp_fnv1a(h, &kk, sizeof kk);
    h = akp_fnv1a(h, &d.sigma, sizeof d.sigma);
    h = akp_fnv1a(h, &d.subdivision_threshold, sizeof d.subdivision_threshold);
    return h;
}

ak_result ak_skin_cor_centers_compute(const ak_skin_cor_desc* desc, const ak_allocator* alloc, ak_vec3_span out_centers) {
    if (!desc || !desc->positions.ptr || !desc->indices.ptr || !desc->joints.ptr || !desc->weights.ptr ||
        !out_centers.ptr)
        return AK_ERR_NULL_ARG;
    ak_skin_cor_desc d = ak_skin_cor_desc_resolved(desc);
    const size_t n = d.positions.count, tris = d.indices.count / 3;
    const uint32_t k = d.influence_count;
    if (n == 0 || tris == 0) return AK_ERR_EMPTY;
    if (k == 0 || k > AK_MAX_INFLUENCES || d.indices.count % 3 != 0 || !(d.sigma > 0.0f) ||
        !(d.subdivision_threshold > 0.0f) || !ak_finitef(d.sigma) || !ak_finitef(d.subdivision_threshold) ||
        d.thread_count > 64)
        return AK_ERR_BAD_ARG;
    if (d.joints.count < n * k || d.weights.count < n * k || out_centers.count < n) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < d.indices.count; ++i)
        if (d.indices.ptr[i] >= n) return AK_ERR_BAD_INDEX;
    size_t joint_count = 1;
    for (size_t i = 0; i < n * k; ++i) {
        if (!(d.weights.ptr[i] >= 0.0f) || !ak_finitef(d.weights.ptr[i])) return AK_ERR_BAD_WEIGHTS;
        if ((size_t)d.joints.ptr[i] + 1 > joint_count) joint_count = (size_t)d.joints.ptr[i] + 1;
    }
    for (size_t i = 0; i < n; ++i)
        if (!ak_vec3_is_finite(d.positions.ptr[i])) return AK_ERR_BAD_DATA;

    cor_state st;
    memset(&st, 0, sizeof st);
    st.alloc = alloc;
    const double thr2 = (double)d.subdivision_threshold * d.subdivision_threshold;
    for (size_t t = 0; t < tris && !st.oom; ++t) {
        const uint32_t* f = &d.indices.ptr[3 * t];
        sparse_w w[3];
        for (int c = 0; c < 3; ++c) vertex_sparse(&d, f[c], &w[c]);
        ak_vec3 p[3] = {d.positions.ptr[f[0]], d.positions.ptr[f[1]], d.positions.ptr[f[2]]};
        const sparse_w* wp[3] = {&w[0], &w[1], &w[2]};
        subdivide(&st, p, wp, thr2, 0);
    }
    ak_result res = st.oom ? AK_ERR_NO_MEMORY : AK_OK;
    uint64_t* keys = NULL;
    size_t key_count = 0;
    uint32_t threads = d.thread_count;
    float* vdense = NULL;
    uint32_t* stamps = NULL;
    if (res == AK_OK && !d.naive) {
        for (size_t t = 0; t < st.tri_count; ++t) key_count += (size_t)st.tris[t].wn * (st.tris[t].wn - 1) / 2;
        keys = (uint64_t*)akp_alloc(alloc, (key_count ? key_count : 1) * sizeof(uint64_t));
        if (!keys) res = AK_ERR_NO_MEMORY;
        else {
            size_t at = 0;
            for (size_t t = 0; t < st.tri_count; ++t) {
                const uint16_t* tj = st.pool_j + st.tris[t].wofs;
                for (uint32_t x = 0; x < st.tris[t].wn; ++x)
                    for (uint32_t y = x + 1; y < st.tris[t].wn; ++y) {
                        uint64_t pair = ((uint64_t)tj[x] << 16) | tj[y]; /* pool joints are sorted */
                        keys[at++] = (pair << 32) | (uint64_t)t;
                    }
            }
            qsort(keys, key_count, sizeof(uint64_t), cmp_u64);
        }
    }
    uint32_t* rep = NULL;
    if (res == AK_OK) {
        rep = (uint32_t*)akp_alloc(alloc, n * sizeof(uint32_t));
        if (!rep) res = AK_ERR_NO_MEMORY;
        else if (d.naive) /* the reference computes every vertex on its own */
            for (size_t v = 0; v < n; ++v) rep[v] = (uint32_t)v;
        else res = find_representatives(&d, alloc, rep);
    }
    if (res == AK_OK) {
        vdense = (float*)akp_calloc(alloc, (size_t)threads * joint_count * sizeof(float));
        stamps = (uint32_t*)akp_calloc(alloc, (size_t)threads * (st.tri_count ? st.tri_count : 1) * sizeof(uint32_t));
        if (!vdense || !stamps) res = AK_ERR_NO_MEMORY;
    }
    if (res == AK_OK) {
        cor_job jobs[64];
        for (uint32_t t = 0; t < threads; ++t) {
            jobs[t].d = &d;
            jobs[t].st = &st;
            jobs[t].keys = d.naive ? NULL : keys;
            jobs[t].key_count = key_count;
            jobs[t].joint_count = joint_count;
            jobs[t].rep = rep;
            jobs[t].thread_index = t;
            jobs[t].thread_count = threads;
            jobs[t].vdense = vdense + (size_t)t * joint_count;
            jobs[t].stamp = stamps + (size_t)t * (st.tri_count ? st.tri_count : 1);
            jobs[t].out = out_centers.ptr;
        }
        akp_run_tasks(cor_worker, jobs, sizeof(jobs[0]), threads);
        /* shared centers; a representative that fell back to its own position (single
         * influence, zero similarity) makes its members fall back to theirs */
        for (size_t v = 0; v < n; ++v) {
            uint32_t r = rep[v];
            if (r == v) continue;
            bool fell_back = memcmp(&out_centers.ptr[r], &d.positions.ptr[r], sizeof(ak_vec3)) == 0;
            out_centers.ptr[v] = fell_back ? d.positions.ptr[v] : out_centers.ptr[r];
        }
    }
    akp_free(alloc, rep);
    akp_free(alloc, keys);
    akp_free(alloc, vdense);
    akp_free(alloc, stamps);
    akp_free(alloc, st.tris);
    akp_free(alloc, st.pool_j);
    akp_free(alloc, st.pool_w);
    return res;
}

/* ---- cache format ------------------------------------------------------------------------ */

size_t ak_skin_cor_centers_encoded_size(size_t vertex_count) {
    if (vertex_count > 0xFFFFFFFFu) return 0;
    return 24u + vertex_count * 12u;
}

ak_result ak_skin_cor_centers_encode(ak_vec3_cspan centers, uint64_t key, ak_u8_span out_buffer, size_t* out_size) {
    if (!centers.ptr || !out_buffer.ptr) return AK_ERR_NULL_ARG;
    size_t size = ak_skin_cor_centers_encoded_size(centers.count);
    if (size == 0) return AK_ERR_BAD_ARG;
    if (out_buffer.count < size) return AK_ERR_SPAN_SMALL;
    unsigned char* p = out_buffer.ptr;
    memcpy(p, "AKCR", 4);
    akp_put_u32(p + 4, 1u);
    akp_put_u32(p + 8, (uint32_t)centers.count);
    akp_put_u32(p + 12, 0u);
    akp_put_u32(p + 16, (uint32_t)(key & 0xFFFFFFFFu));
    akp_put_u32(p + 20, (uint32_t)(key >> 32));
    for (size_t i = 0; i < centers.count; ++i) {
        akp_put_f32(p + 24 + 12 * i, centers.ptr[i].x);
        akp_put_f32(p + 28 + 12 * i, centers.ptr[i].y);
        akp_put_f32(p + 32 + 12 * i, centers.ptr[i].z);
    }
    if (out_size) *out_size = size;
    return AK_OK;
}

ak_result ak_skin_cor_centers_decode(ak_u8_cspan buffer, uint64_t key, ak_vec3_span out_centers) {
    if (!buffer.ptr || !out_centers.ptr) return AK_ERR_NULL_ARG;
    if (buffer.count < 24 || memcmp(buffer.ptr, "AKCR", 4) != 0 || akp_get_u32(buffer.ptr + 4) != 1u)
        return AK_ERR_PARSE;
    size_t vc = akp_get_u32(buffer.ptr + 8);
    if (buffer.count < ak_skin_cor_centers_encoded_size(vc)) return AK_ERR_PARSE;
    uint64_t k = (uint64_t)akp_get_u32(buffer.ptr + 16) | ((uint64_t)akp_get_u32(buffer.ptr + 20) << 32);
    if (k != key) return AK_ERR_NOT_FOUND;
    if (out_centers.count < vc) return AK_ERR_SPAN_SMALL;
    const unsigned char* p = buffer.ptr + 24;
    for (size_t i = 0; i < vc; ++i)
        out_centers.ptr[i] = ak_vec3_make(akp_get_f32(p + 12 * i), akp_get_f32(p + 12 * i + 4), akp_get_f32(p + 12 * i + 8));
    return AK_OK;
}

ak_result ak_skin_cor_centers_write_file(const char* path, ak_vec3_cspan centers, uint64_t key) {
    if (!path || !centers.ptr) return AK_ERR_NULL_ARG;
    size_t size = ak_skin_cor_centers_encoded_size(centers.count);
    if (size == 0) return AK_ERR_BAD_ARG;
    unsigned char* buf = (unsigned char*)malloc(size);
    if (!buf) return AK_ERR_NO_MEMORY;
    ak_u8_span span = {buf, size};
    ak_result r = ak_skin_cor_centers_encode(centers, key, span, NULL);
    if (r == AK_OK) r = akp_write_file(path, buf, size);
    free(buf);
    return r;
}

ak_result ak_skin_cor_centers_read_file(const char* path, uint64_t key, ak_vec3_span out_centers) {
    if (!path || !out_centers.ptr) return AK_ERR_NULL_ARG;
    unsigned char* buf = NULL;
    size_t size = 0;
    ak_result r = akp_read_file(path, &buf, &size);
    if (r != AK_OK) return r;
    ak_u8_cspan span = {buf, size};
    r = ak_skin_cor_centers_decode(span, key, out_centers);
    free(buf);
    return r;
}

ak_result ak_skin_cor_centers_cached(const ak_skin_cor_desc* desc, const char* cache_path, const ak_allocator* alloc,
                                     ak_vec3_span out_centers, bool* out_from_cache) {
    if (out_from_cache) *out_from_cache = false;
    if (!desc || !out_centers.ptr) return AK_ERR_NULL_ARG;
    const uint64_t key = ak_skin_cor_key(desc);
    if (cache_path && out_centers.count >= desc->positions.count) {
        ak_vec3_span part = {out_centers.ptr, desc->positions.count};
        if (ak_skin_cor_centers_read_file(cache_path, key, part) == AK_OK) {
            /* the key covers positions.count through the position bytes, so sizes agree */
            if (out_from_cache) *out_from_cache = true;
            return AK_OK;
        }
    }
    ak_result r = ak_skin_cor_centers_compute(desc, alloc, out_centers);
    if (r == AK_OK && cache_path) {
        ak_vec3_cspan c = {out_centers.ptr, desc->positions.count};
        (void)ak_skin_cor_centers_write_file(cache_path, c, key);
    }
    return r;
}
