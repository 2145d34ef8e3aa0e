/* animkit blendshape: blend shapes (morph targets), dense and sparse.
 *
 * What it does: per-vertex interpolation between key shapes, in both textbook forms:
 *   full          p = sum_k w_k b_k                        (ak_blendshape_full_job)
 *   differential  p = b_0 + sum_k w_k (b_k - b_0) = b_0 + D w (every other job here)
 * The two agree when the full-form weights sum to one (w_0 = 1 - sum_{k>=1} w_k).
 * Deltas d_k = b_k - b_0 are stored target-major ([target][vertex], glTF's layout, the same as
 * ak_mesh.morph_positions). An ak_blendshape_set is the built, immutable form: each target's
 * deltas are kept densely, or sparsely (only the vertices that move, with their indices) when
 * that is smaller, which is much faster for local targets (a blink, a smile) on big meshes.
 * Normals are blended the same way (n = n_0 + sum_k w_k dn_k) and renormalised.
 * Expression transfer: the set stores only D, so running it over another base b_0' with the same
 * topology (same vertex count and order) gives b_0' + D w.
 *
 * Order with skinning: blend shapes are applied first, in bind (mesh) space, and the result is
 * then skinned (glTF 2.0 section 3.7.2.2): feed out_positions/out_normals to the skin job.
 * Weights come from anywhere: set directly, or sampled from a clip's morph-weight channel
 * (glTF "weights" animations) and passed in as an ak_f32_cspan, one weight per target.
 * Weights may be negative or above one (glTF allows both); they must be finite.
 *
 * What it does NOT do: sample animations (clip.h), skin (skin.h), read files (io.h), or blend
 * tangents or UVs.
 *
 * Usage:
 *     ak_blendshape_set* set = NULL;
 *     ak_blendshape_set_desc d = {
 *         .vertex_count = mesh->vertex_count, .target_count = mesh->morph_target_count,
 *         .deltas = { mesh->morph_positions, mesh->vertex_count * mesh->morph_target_count },
 *         .threshold = 1e-6f,                    // drop deltas shorter than this
 *     };
 *     if (ak_blendshape_set_create(&d, NULL, &set) != AK_OK) return 1;
 *     float w[2] = { 0.25f, 1.0f };              // e.g. sampled from a clip at time t
 *     ak_blendshape_job job = {
 *         .set = set, .weights = AK_SPAN(w),
 *         .base_positions = { mesh->positions, mesh->vertex_count },
 *         .out_positions = { morphed, mesh->vertex_count },
 *     };
 *     ak_result r = ak_blendshape_run(&job);      // then skin `morphed`
 *     ak_blendshape_set_destroy(set);
 *
 * Ownership and threading: a set is one allocation, read-only after create; it may be shared
 * by any number of threads. Jobs never allocate and write only their output spans, so jobs
 * with distinct outputs may run in parallel. Nothing keeps a caller pointer after a call.
 */
#ifndef ANIMKIT_BLENDSHAPE_H
#define ANIMKIT_BLENDSHAPE_H

#include "mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- dense jobs over raw arrays --------------------------------------------------------- */

/* Differential blend over dense, target-major deltas: out = base + sum_k w_k deltas[k].
 * K = weights.count targets, V = base_positions.count vertices. */
typedef struct ak_blendshape_dense_job {
    ak_f32_cspan weights;          /* required, K finite weights (K may be 0: out = base) */
    ak_vec3_cspan base_positions;  /* required, V > 0 positions b_0 (or b_0' to transfer) */
    ak_vec3_cspan deltas;          /* K * V position deltas, target-major; may be empty if K = 0 */
    ak_vec3_cspan base_normals;    /* V unit normals; needed only with out_normals */
    ak_vec3_cspan normal_deltas;   /* K * V normal deltas; empty -> normals are not morphed */
    ak_vec3_span out_positions;    /* required, count >= V; may be base_positions itself, must
                                      not overlap the deltas */
    ak_vec3_span out_normals;      /* optional, count >= V; unit; may be base_normals itself */
} ak_blendshape_dense_job;

/* First rule the job breaks: AK_ERR_NULL_ARG (weights.ptr NULL with K > 0, base_positions or
 * out_positions empty, deltas empty with K > 0, out_normals set without base_normals),
 * AK_ERR_BAD_ARG (deltas.count != K * V, base_normals.count != V, normal_deltas non-empty and
 * != K * V), AK_ERR_SPAN_SMALL (an output shorter than V), AK_ERR_BAD_DATA (a weight is NaN or
 * infinite). A zero-initialised job gives AK_ERR_NULL_ARG. Deltas are not scanned (O(K V));
 * check them once with ak_blendshape_set_create or ak_blendshape_deltas_are_finite. */
AK_API ak_result ak_blendshape_dense_validate(const ak_blendshape_dense_job* job);
/* Validate, then blend. Targets whose weight is exactly zero are skipped. Normals: base
 * normals plus the weighted normal deltas (if any), renormalised; a sum of (near) zero length
 * gives (0, 1, 0). Writes nothing when validation fails. */
AK_API ak_result ak_blendshape_dense_run(const ak_blendshape_dense_job* job);

/* Full form: out = sum_k w_k shapes[k], absolute key shapes, target-major (K = weights.count,
 * V = shapes.count / K). The result is only a meaningful shape when the weights sum to one. */
typedef struct ak_blendshape_full_job {
    ak_f32_cspan weights;          /* required, K > 0 finite weights */
    ak_vec3_cspan shapes;          /* required, K * V absolute positions b_k */
    ak_vec3_cspan shape_normals;   /* K * V unit normals; needed only with out_normals */
    ak_vec3_span out_positions;    /* required, count >= V; must not overlap shapes */
    ak_vec3_span out_normals;      /* optional, count >= V; unit */
} ak_blendshape_full_job;

/* AK_ERR_NULL_ARG (weights or shapes or out_positions empty, out_normals set without
 * shape_normals), AK_ERR_BAD_ARG (shapes.count not a multiple of K, shape_normals.count !=
 * shapes.count), AK_ERR_SPAN_SMALL (an output shorter than V), AK_ERR_BAD_DATA (NaN/inf weight).
 * A zero-initialised job gives AK_ERR_NULL_ARG. */
AK_API ak_result ak_blendshape_full_validate(const ak_blendshape_full_job* job);
/* Validate, then blend. Normals: sum_k w_k n_k renormalised; a sum of (near) zero length gives
 * (0, 1, 0), the fallback ak_normals_compute uses. Writes nothing when validation fails. */
AK_API ak_result ak_blendshape_full_run(const ak_blendshape_full_job* job);

/* Deltas of absolute key shapes: out_deltas[k*V + i] = shapes[k*V + i] - base[i].
 * Needs shapes.count a multiple of base.count (V > 0) and out_deltas.count >= shapes.count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_blendshape_deltas_from_shapes(ak_vec3_cspan base, ak_vec3_cspan shapes,
                                                  ak_vec3_span out_deltas);

/* True when every component is finite (empty -> true). */
AK_API bool ak_blendshape_deltas_are_finite(ak_vec3_cspan deltas);

/* ---- blending straight from an ak_mesh -------------------------------------------------- */

/* Differential blend of a mesh's own morph targets (ak_mesh.morph_positions/morph_normals). */
typedef struct ak_blendshape_mesh_job {
    const ak_mesh* mesh;           /* required, morph_target_count may be 0 (out = positions) */
    ak_f32_cspan weights;          /* morph_target_count weights; empty -> mesh->morph_weights */
    ak_vec3_span out_positions;    /* required, count >= vertex_count */
    ak_vec3_span out_normals;      /* optional, count >= vertex_count; needs mesh->normals */
} ak_blendshape_mesh_job;

/* AK_ERR_NULL_ARG (mesh or out_positions NULL, mesh arrays missing, out_normals set but the
 * mesh has no normals), AK_ERR_BAD_ARG (weights.count != morph_target_count),
 * AK_ERR_SPAN_SMALL, AK_ERR_BAD_DATA (NaN/inf weight). Zero-initialised -> AK_ERR_NULL_ARG. */
AK_API ak_result ak_blendshape_mesh_validate(const ak_blendshape_mesh_job* job);
/* Validate, then blend (same kernel and normal rule as ak_blendshape_dense_run). */
AK_API ak_result ak_blendshape_mesh_run(const ak_blendshape_mesh_job* job);

/* ---- built sets: dense or sparse storage ------------------------------------------------ */

typedef enum ak_blendshape_storage {
    AK_BLENDSHAPE_STORAGE_AUTO = 0, /* default: per target, sparse when at most a third of the
                                       vertices move, dense otherwise (bench_blendshape: sparse
                                       wins up to roughly half) */
    AK_BLENDSHAPE_STORAGE_DENSE,    /* every target keeps all V deltas */
    AK_BLENDSHAPE_STORAGE_SPARSE,   /* every target keeps only its moving vertices */
    AK_BLENDSHAPE_STORAGE_COUNT
} ak_blendshape_storage;

typedef struct ak_blendshape_set_desc {
    size_t vertex_count;           /* required, V > 0 */
    size_t target_count;           /* required, K > 0 */
    ak_vec3_cspan deltas;          /* required, K * V position deltas b_k - b_0, target-major */
    ak_vec3_cspan normal_deltas;   /* K * V normal deltas; empty -> the set has none */
    ak_blendshape_storage storage; /* 0 -> AK_BLENDSHAPE_STORAGE_AUTO */
    float threshold;               /* length units: a vertex is kept in a target when its
                                      position or normal delta is longer than this; shorter
                                      deltas are dropped (zeroed) in every storage, so results
                                      do not depend on the storage; 0 -> only exact zeros drop */
} ak_blendshape_set_desc;

typedef struct ak_blendshape_set ak_blendshape_set;

/* A desc that points at a mesh's morph arrays (no copy; the mesh must outlive the create call,
 * not the set). Fields the mesh lacks stay zero. mesh NULL gives a zero desc. */
AK_API ak_blendshape_set_desc ak_blendshape_set_desc_from_mesh(const ak_mesh* mesh);

/* Build a set (the dense-to-sparse builder): copies the deltas, dropping the ones under the
 * threshold. Returns AK_ERR_NULL_ARG (desc, out_set or deltas NULL), AK_ERR_EMPTY (V or K 0),
 * AK_ERR_BAD_ARG (deltas.count or non-empty normal_deltas.count != K * V, threshold negative
 * or NaN, unknown storage, counts that overflow), AK_ERR_BAD_DATA (a NaN/inf delta),
 * AK_ERR_NO_MEMORY. On failure *out_set is NULL. alloc NULL -> malloc/free. */
AK_API ak_result ak_blendshape_set_create(const ak_blendshape_set_desc* desc, const ak_allocator* alloc,
                                          ak_blendshape_set** out_set);
/* NULL is a no-op. */
AK_API void ak_blendshape_set_destroy(ak_blendshape_set* set);

AK_API size_t ak_blendshape_set_vertex_count(const ak_blendshape_set* set);  /* NULL -> 0 */
AK_API size_t ak_blendshape_set_target_count(const ak_blendshape_set* set);  /* NULL -> 0 */
AK_API bool ak_blendshape_set_has_normals(const ak_blendshape_set* set);     /* NULL -> false */
/* Vertices kept for a target after thresholding (V for a dense target); 0 when out of range. */
AK_API size_t ak_blendshape_set_moved_count(const ak_blendshape_set* set, size_t target_index);
/* True when that target is stored sparsely; false when dense or out of range. */
AK_API bool ak_blendshape_set_target_is_sparse(const ak_blendshape_set* set, size_t target_index);
/* Bytes of the set's single allocation (0 for NULL). */
AK_API size_t ak_blendshape_set_memory_size(const ak_blendshape_set* set);

/* Differential blend of a set over a base: out = base + sum_k w_k d_k. */
typedef struct ak_blendshape_job {
    const ak_blendshape_set* set;  /* required */
    ak_f32_cspan weights;          /* required, count == target count, finite */
    ak_vec3_cspan base_positions;  /* required, count == vertex count: b_0, or b_0' to transfer */
    ak_vec3_cspan base_normals;    /* count == vertex count; needed only with out_normals */
    ak_vec3_span out_positions;    /* required, count >= V; may be base_positions itself */
    ak_vec3_span out_normals;      /* optional, count >= V; may be base_normals itself */
} ak_blendshape_job;

/* AK_ERR_NULL_ARG (set, weights, base_positions or out_positions empty; out_normals set without
 * base_normals), AK_ERR_BAD_ARG (weights.count != K, base_positions.count or base_normals.count
 * != V), AK_ERR_SPAN_SMALL (an output shorter than V), AK_ERR_BAD_DATA (NaN/inf weight).
 * A zero-initialised job gives AK_ERR_NULL_ARG. */
AK_API ak_result ak_blendshape_validate(const ak_blendshape_job* job);
/* Validate, then blend. Targets whose weight is exactly zero are skipped. Normals: the set's
 * normal deltas (if any) are added to the base normals, then every normal is renormalised; a
 * sum of (near) zero length gives (0, 1, 0), the fallback ak_normals_compute uses.
 * Writes nothing when validation fails. */
AK_API ak_result ak_blendshape_run(const ak_blendshape_job* job);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_BLENDSHAPE_H */
