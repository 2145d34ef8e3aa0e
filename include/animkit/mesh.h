/* animkit mesh: triangle meshes with optional skin weights and morph targets.
 *
 * What it does: one container type shared by the skinning, blend-shape, import, builtin and
 * rendering modules, plus the geometric queries they all need: bounds, normals, enclosed
 * volume, closed/consistently-oriented checks, self-intersection counts, and skin-weight
 * validation and clean-up (limit to k influences, renormalise).
 *
 * What it does NOT do: deform (see skin.h, blendshape.h) or read files (see io.h).
 *
 * Usage:
 *     ak_mesh* mesh = NULL;
 *     ak_mesh_desc d = { .vertex_count = 3, .triangle_count = 1, .has_normals = true };
 *     if (ak_mesh_create(&d, NULL, &mesh) != AK_OK) return 1;
 *     mesh->positions[1] = ak_vec3_make(1, 0, 0);
 *     mesh->positions[2] = ak_vec3_make(0, 1, 0);
 *     mesh->indices[0] = 0; mesh->indices[1] = 1; mesh->indices[2] = 2;
 *     ak_mesh_compute_normals(mesh);                // counter-clockwise -> +Z
 *     ak_mesh_destroy(mesh);
 *
 * Ownership: ak_mesh_create makes one allocation holding the struct and every array; the
 * caller fills the arrays once and then treats the mesh as read-only (it may then be read from
 * any number of threads). Triangles are counter-clockwise seen from outside (glTF's rule).
 */
#ifndef ANIMKIT_MESH_H
#define ANIMKIT_MESH_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Most influences a vertex may carry. */
#define AK_MAX_INFLUENCES 8

typedef struct ak_mesh_desc {
    size_t vertex_count;       /* required, > 0 */
    size_t triangle_count;     /* 0 -> a point cloud (no indices) */
    uint32_t influence_count;  /* joints per vertex, 0 (unskinned) .. AK_MAX_INFLUENCES */
    size_t morph_target_count; /* 0 -> none */
    bool has_normals;          /* false -> normals == NULL */
    bool has_uvs;              /* false -> uvs == NULL */
    bool has_colors;           /* false -> colors == NULL */
    bool has_morph_normals;    /* false -> morph_normals == NULL */
    const char* name;          /* NULL -> "" ; copied, truncated to AK_NAME_SIZE-1 */
    bool has_tangents;         /* false -> tangents == NULL */
    bool has_morph_tangents;   /* false -> morph_tangents == NULL */
} ak_mesh_desc;

typedef struct ak_mesh {
    char name[AK_NAME_SIZE];
    size_t vertex_count;
    size_t triangle_count;
    uint32_t influence_count;   /* per vertex; 0 when unskinned */
    size_t morph_target_count;
    ak_vec3* positions;         /* [vertex_count], mesh (bind) space */
    ak_vec3* normals;           /* [vertex_count] unit, or NULL */
    ak_vec2* uvs;               /* [vertex_count], or NULL */
    ak_vec4* colors;            /* [vertex_count] linear RGBA, or NULL */
    uint32_t* indices;          /* [3 * triangle_count], counter-clockwise from outside */
    uint16_t* joints;           /* [vertex_count * influence_count] palette indices: in a
                                   scene, slots of the mesh's skin (ak_scene_skin_palette) */
    float* weights;             /* [vertex_count * influence_count], >= 0, sum 1 per vertex */
    ak_vec3* morph_positions;   /* [morph_target_count * vertex_count] deltas, target-major */
    ak_vec3* morph_normals;     /* same layout, or NULL */
    float* morph_weights;       /* [morph_target_count] default weights (glTF mesh.weights) */
    char (*morph_names)[AK_NAME_SIZE]; /* [morph_target_count], "" when unnamed */
    ak_vec4* tangents;          /* [vertex_count] (xyz unit, w = +1 or -1: bitangent =
                                   w * cross(normal, tangent), glTF's TANGENT), or NULL.
                                   Carried through import, copy and export; the deformers
                                   (skin.h, blendshape.h) do not move them */
    ak_vec3* morph_tangents;    /* [morph_target_count * vertex_count] xyz deltas, or NULL */
} ak_mesh;

/* Allocate a mesh with every array zeroed (weights zero, joints zero, indices zero).
 * Returns AK_ERR_NULL_ARG (desc or out_mesh NULL), AK_ERR_EMPTY (vertex_count 0),
 * AK_ERR_BAD_ARG (influence_count > AK_MAX_INFLUENCES, counts that overflow, more than 2^32
 * vertices with triangles, or an allocator with only one of alloc/free set),
 * AK_ERR_NO_MEMORY. On failure *out_mesh is NULL. */
AK_API ak_result ak_mesh_create(const ak_mesh_desc* desc, const ak_allocator* alloc, ak_mesh** out_mesh);
/* Free a mesh made by ak_mesh_create or a loader; NULL is a no-op. */
AK_API void ak_mesh_destroy(ak_mesh* mesh);
/* Deep copy (same allocator rules as create). */
AK_API ak_result ak_mesh_clone(const ak_mesh* mesh, const ak_allocator* alloc, ak_mesh** out_mesh);

/* Check indices < vertex_count and every position/normal finite: AK_ERR_BAD_INDEX or
 * AK_ERR_BAD_DATA (diag, optional, says which vertex or triangle). */
AK_API ak_result ak_mesh_validate(const ak_mesh* mesh, ak_diag* diag);

/* Axis-aligned bounds of the positions (as ak_points_bounds); NULL or empty gives zeros. */
AK_API void ak_mesh_bounds(const ak_mesh* mesh, ak_vec3* out_min, ak_vec3* out_max);
/* Bounds of any point array, skipping non-finite points; no finite point gives zeros. */
AK_API void ak_points_bounds(ak_vec3_cspan points, ak_vec3* out_min, ak_vec3* out_max);

/* Area-weighted vertex normals of triangles over positions, written to out_normals
 * (count >= positions.count). Vertices on no triangle, or on only degenerate ones, get (0,1,0).
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_INDEX. */
AK_API ak_result ak_normals_compute(ak_vec3_cspan positions, ak_u32_cspan indices, ak_vec3_span out_normals);
/* Elements of uint32 scratch ak_normals_compute_welded needs for vertex_count vertices
 * (vertex_count plus a hash table of twice that, rounded up to a power of two). SIZE_MAX when
 * that would overflow. */
AK_API size_t ak_normals_welded_scratch_count(size_t vertex_count);
/* Area-weighted vertex normals like ak_normals_compute, except that vertices at the same
 * position (bitwise equal coordinates, -0 equal to +0) share one normal: the normalised sum of
 * the faces around all of them. This shades an unwelded mesh (one vertex per face corner, as
 * OBJ files without normals give) smooth instead of faceted; meshes whose hard edges are
 * meant (split normals) should keep their own. Non-finite positions are never welded.
 * scratch.count >= ak_normals_welded_scratch_count(positions.count); it is overwritten.
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL (out_normals or scratch), AK_ERR_BAD_INDEX.
 *     uint32_t* scratch = malloc(ak_normals_welded_scratch_count(n) * sizeof(uint32_t));
 *     ak_normals_compute_welded(positions, indices,
 *                               (ak_u32_span){scratch, ak_normals_welded_scratch_count(n)},
 * normals); */
AK_API ak_result ak_normals_compute_welded(ak_vec3_cspan positions, ak_u32_cspan indices,
                                           ak_u32_span scratch, ak_vec3_span out_normals);
/* ak_normals_compute on the mesh's own arrays (no-op when normals == NULL). */
AK_API ak_result ak_mesh_compute_normals(ak_mesh* mesh);

/* Signed volume enclosed by a closed triangle mesh (divergence theorem, double precision):
 * positive when triangles are counter-clockwise seen from outside. Open meshes give the
 * volume of the cone to the origin (meaningless but finite). */
AK_API double ak_volume_compute(ak_vec3_cspan positions, ak_u32_cspan indices);

/* Number of pairs of triangles that intersect without being adjacent: two triangles are
 * adjacent when they share a vertex, by index or by position (vertices at bitwise-equal
 * positions count as one, so a UV seam's split vertices do not make neighbours look
 * intersecting). Triangles are closed sets: touching at a point or along an edge counts.
 * The test per pair is exact in its signs up to the rounding of double-precision orientation
 * determinants on the float input (Plucker-style edge/triangle tests; the coplanar case in 2D);
 * degenerate (zero-area) triangles never count. A uniform grid of triangle bounds finds the
 * candidate pairs (about 30 ms for 50k triangles). Temporary memory comes from malloc (about
 * 60 bytes per triangle and 12 per vertex). out_pairs is optional (count 0): the first
 * out_pairs.count / 2 pairs found are written as triangle indices (lower first), in an
 * unspecified but deterministic order; *out_count is always the full count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_INDEX, AK_ERR_BAD_DATA (a non-finite position),
 * AK_ERR_BAD_ARG (more than 2^32 vertices or 2^29 triangles), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_mesh_self_intersections(ak_vec3_cspan positions, ak_u32_cspan indices,
                                            ak_u32_span out_pairs, size_t* out_count);
/* The same closed triangle-triangle test for one pair (a[3], b[3]): true when they share a
 * point. Degenerate or non-finite triangles give false. */
AK_API bool ak_triangles_intersect(const ak_vec3 a[3], const ak_vec3 b[3]);

/* True when every edge is shared by exactly two triangles that traverse it in opposite
 * directions (closed, edge-manifold and consistently oriented). Degenerate triangles (a
 * repeated index), out-of-range indices and meshes without triangles give false. Sorts the
 * 3 * triangle_count directed edges in temporary heap memory (malloc); false if that fails. */
AK_API bool ak_mesh_is_closed_oriented(const ak_mesh* mesh);

/* Check skin weights: each finite and >= 0, per-vertex sum within tolerance of 1
 * (tolerance 0 -> 1e-3), joint indices < joint_count. Returns AK_ERR_BAD_WEIGHTS or
 * AK_ERR_BAD_INDEX with diag naming the vertex; AK_OK for an unskinned mesh. */
AK_API ak_result ak_mesh_validate_weights(const ak_mesh* mesh, size_t joint_count, float tolerance, ak_diag* diag);

/* Clean a per-vertex weight array in place: NaN/negative -> 0, duplicate joints merged,
 * sorted by decreasing weight (ties: lower joint first), at most max_influences kept
 * (0 -> 4), weights below min_weight dropped (the largest always stays), renormalised to sum
 * to 1 (within 1e-6). A vertex whose weights are all zero gets weight 1 on its first joint
 * (documented fallback). influence_count is the array's stride (any value; the first 64
 * slots of a vertex are read, so wide strides gathered from several glTF JOINTS_n sets work);
 * slots past the kept ones are zeroed (joint 0, weight 0). */
AK_API void ak_weights_normalize(uint16_t* joints, float* weights, size_t vertex_count, uint32_t influence_count,
                                 uint32_t max_influences, float min_weight);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_MESH_H */
